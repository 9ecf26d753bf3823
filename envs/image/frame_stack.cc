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
    : EnvWrapper(std::move(env), "FrameStack") {
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
  EnvSpec& spec = mutable_spec();
  spec.observation_size = static_cast<int>(total);
  spec.frame_height = shape.height;
  spec.frame_width = shape.width;
  spec.frame_stack = config.stack;
  stacked_.resize(total);
}

void FrameStack::OnReset(std::optional<uint64_t> seed) {
  EnvWrapper::OnReset(seed);
  for (int slot = 0; slot < spec().frame_stack; ++slot) Store(slot);
}

StepResult FrameStack::OnStep(std::span<const float> action) {
  const StepResult result = env_->Step(action);
  // Shift the stack one frame towards the front and append the new frame.
  std::copy(stacked_.begin() + static_cast<std::ptrdiff_t>(frame_size_), stacked_.end(),
            stacked_.begin());
  Store(spec().frame_stack - 1);
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
  if (!started()) throw std::logic_error("FrameStack: call Reset() before frame()");
  return env_->image();
}

}  // namespace rl::envs
