#include "envs/image/frame_stack.h"

#include <algorithm>
#include <climits>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/check.h"

namespace rl::envs {

FrameStack::FrameStack(std::unique_ptr<ImageSource> env, const ImagePipelineConfig& config)
    : env_(std::move(env)) {
  if (env_ == nullptr) throw std::invalid_argument("FrameStack: the wrapped env must not be null");
  config.Validate();
  const ImageShape shape = env_->image_shape();
  if (shape.channels != 1) {
    throw std::invalid_argument("FrameStack: the wrapped images must be grayscale, got " +
                                std::to_string(shape.channels) + " channels");
  }
  frame_size_ = shape.bytes();
  const std::size_t total = frame_size_ * static_cast<std::size_t>(config.stack);
  if (total > static_cast<std::size_t>(INT_MAX)) {
    throw std::invalid_argument("FrameStack: stack * height * width must fit in an int, got " +
                                std::to_string(total));
  }
  spec_ = env_->spec();
  spec_.observation_size = static_cast<int>(total);
  spec_.frame_height = shape.height;
  spec_.frame_width = shape.width;
  spec_.frame_stack = config.stack;
  stacked_.resize(total);
}

void FrameStack::Reset(uint64_t seed) {
  env_->Reset(seed);
  for (int slot = 0; slot < spec_.frame_stack; ++slot) Store(slot);
  has_frames_ = true;
}

void FrameStack::Reset() {
  env_->Reset();
  for (int slot = 0; slot < spec_.frame_stack; ++slot) Store(slot);
  has_frames_ = true;
}

StepResult FrameStack::Step(int action) {
  if (!has_frames_) throw std::logic_error("FrameStack: call Reset() before Step()");
  return Push(env_->Step(action));
}

StepResult FrameStack::StepContinuous(std::span<const float> action) {
  if (!has_frames_) throw std::logic_error("FrameStack: call Reset() before Step()");
  return Push(env_->StepContinuous(action));
}

StepResult FrameStack::Push(StepResult result) {
  // Shift the stack one frame towards the front and append the new frame.
  std::copy(stacked_.begin() + static_cast<std::ptrdiff_t>(frame_size_), stacked_.end(),
            stacked_.begin());
  Store(spec_.frame_stack - 1);
  return result;
}

void FrameStack::Store(int slot) {
  const std::span<const uint8_t> pixels = env_->image();
  RL_CHECK(pixels.size() == frame_size_)
      << "image() has " << pixels.size() << " bytes, expected " << frame_size_;
  const auto out =
      stacked_.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(slot) * frame_size_);
  std::transform(pixels.begin(), pixels.end(), out,
                 [](uint8_t p) { return static_cast<float>(p) / 255.0f; });
}

std::span<const uint8_t> FrameStack::frame() const {
  if (!has_frames_) throw std::logic_error("FrameStack: call Reset() before frame()");
  return env_->image();
}

void FrameStack::Render(std::vector<uint8_t>* rgb, int* width, int* height) const {
  env_->Render(rgb, width, height);
}

void FrameStack::RenderSized(int width, int height, std::vector<uint8_t>* rgb) const {
  env_->RenderSized(width, height, rgb);
}

}  // namespace rl::envs
