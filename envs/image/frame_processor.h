// FrameProcessor: the second stage of the pixel pipeline (pixel_env.h). Turns the RGB image of the
// wrapped ImageSource into a grayscale frame, crops it and resizes it with area interpolation, as
// in Mnih et al. (2015) and Gymnasium's AtariPreprocessing (grayscale_obs, screen_size).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "envs/env.h"
#include "envs/image/image_source.h"
#include "envs/image/pixel_env.h"
#include "envs/wrapper.h"

namespace rl::envs {

/// Wraps an RGB ImageSource; its image() is the processed grayscale frame of the current state.
/// spec() and observation() are the wrapped env's. Not thread-safe.
class FrameProcessor : public EnvWrapper<ImageSource, ImageSource> {
 public:
  /// Takes ownership of `env` and reads config's crop_top, crop_bottom, crop_left, crop_right,
  /// width and height. Allocates all frame buffers. Throws std::invalid_argument if env is null,
  /// its images are not RGB, config.Validate() fails, or the crop leaves no pixel of its images.
  FrameProcessor(std::unique_ptr<ImageSource> env, const ImagePipelineConfig& config);

  // Reset and Step reset or step the wrapped env, then process its image.

  /// Grayscale frames of width x height, or of the cropped size when both are 0.
  ImageShape image_shape() const override { return shape_; }
  /// The wrapped image converted to grayscale (cv::COLOR_RGB2GRAY: 0.299 R + 0.587 G + 0.114 B,
  /// rounded), cropped, then resized with cv::INTER_AREA.
  std::span<const uint8_t> image() const override;

 private:
  void OnReset(std::optional<uint64_t> seed) override;
  StepResult OnStep(std::span<const float> action) override;
  // Computes image() from the wrapped env's current image.
  void Process();

  int crop_left_;
  int crop_top_;
  ImageShape cropped_;            // Grayscale shape after the crop.
  ImageShape shape_;              // Output shape.
  bool resize_;                   // Whether shape_ differs from cropped_.
  std::vector<uint8_t> gray_;     // The cropped grayscale frame.
  std::vector<uint8_t> resized_;  // The output when resize_.
};

}  // namespace rl::envs
