#include "envs/image/frame_processor.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/check.h"

namespace rl::envs {

FrameProcessor::FrameProcessor(std::unique_ptr<ImageSource> env, const ImagePipelineConfig& config)
    : EnvWrapper(std::move(env), "FrameProcessor"),
      crop_left_(config.crop_left),
      crop_top_(config.crop_top) {
  config.Validate();
  const ImageShape in = env_->image_shape();
  if (in.channels != 3) {
    throw std::invalid_argument("FrameProcessor: the wrapped images must be RGB, got " +
                                std::to_string(in.channels) + " channels");
  }

  // The crop must leave at least one pixel each way (64-bit sums: the crops can be large).
  const int64_t cropped_width =
      int64_t{in.width} - int64_t{config.crop_left} - int64_t{config.crop_right};
  const int64_t cropped_height =
      int64_t{in.height} - int64_t{config.crop_top} - int64_t{config.crop_bottom};
  if (cropped_width <= 0 || cropped_height <= 0) {
    throw std::invalid_argument(
        "FrameProcessor: crop_left + crop_right must be below the frame width and crop_top + "
        "crop_bottom below its height; the frame is " +
        std::to_string(in.width) + "x" + std::to_string(in.height) + ", the crops leave " +
        std::to_string(cropped_width) + "x" + std::to_string(cropped_height));
  }
  cropped_ = ImageShape{.width = static_cast<int>(cropped_width),
                        .height = static_cast<int>(cropped_height),
                        .channels = 1};
  shape_ = config.width == 0
               ? cropped_
               : ImageShape{.width = config.width, .height = config.height, .channels = 1};
  resize_ = shape_ != cropped_;
  gray_.resize(cropped_.bytes());
  if (resize_) resized_.resize(shape_.bytes());
}

void FrameProcessor::OnReset(std::optional<uint64_t> seed) {
  EnvWrapper::OnReset(seed);
  Process();
}

StepResult FrameProcessor::OnStep(std::span<const float> action) {
  const StepResult result = env_->Step(action);
  Process();
  return result;
}

void FrameProcessor::Process() {
  // OpenCV headers over our own buffers: cvtColor and resize see outputs of the right size and
  // type and write into them without reallocating. OpenCV has no read-only Mat, hence the
  // const_cast; the source is only read.
  const std::span<const uint8_t> rgb = env_->image();
  const ImageShape in = env_->image_shape();
  RL_CHECK(rgb.size() == in.bytes())
      << "image() has " << rgb.size() << " bytes, expected " << in.bytes();
  const cv::Mat source(in.height, in.width, CV_8UC3, const_cast<uint8_t*>(rgb.data()));

  // Crop, then convert to grayscale: the conversion is per pixel, so this gives the same frame as
  // converting first, and converts fewer pixels.
  const cv::Mat cropped = source(cv::Rect(crop_left_, crop_top_, cropped_.width, cropped_.height));
  cv::Mat gray(cropped_.height, cropped_.width, CV_8UC1, gray_.data());
  cv::cvtColor(cropped, gray, cv::COLOR_RGB2GRAY);
  RL_CHECK(gray.data == gray_.data()) << "cvtColor reallocated its output";

  // Area resize to the output size.
  if (resize_) {
    cv::Mat resized(shape_.height, shape_.width, CV_8UC1, resized_.data());
    cv::resize(gray, resized, resized.size(), 0, 0, cv::INTER_AREA);
    RL_CHECK(resized.data == resized_.data()) << "resize reallocated its output";
  }
}

std::span<const uint8_t> FrameProcessor::image() const {
  if (!started()) throw std::logic_error("FrameProcessor: call Reset() before image()");
  return resize_ ? resized_ : gray_;
}

}  // namespace rl::envs
