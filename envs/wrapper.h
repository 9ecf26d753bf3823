// EnvWrapper: what every wrapper (TimeLimit, the stages of the image pipeline) shares: it owns the
// env it wraps, starts with that env's spec, resets it with the same seed, and forwards the
// observation, the frame and the pictures unless it overrides them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "envs/env.h"

namespace rl::envs {

/// A `Base` (Env, or an Env with more to show such as ImageSource) wrapping an `Inner`. Derived
/// classes implement OnStep (usually stepping wrapped() and changing the result) and may change
/// their spec in their constructor (mutable_spec()). Not thread-safe.
template <class Base = Env, class Inner = Env>
class EnvWrapper : public Base {
 public:
  std::span<const float> observation() const override { return env_->observation(); }
  std::span<const uint8_t> frame() const override { return env_->frame(); }
  void Render(std::vector<uint8_t>* rgb, int* width, int* height) const override {
    env_->Render(rgb, width, height);
  }
  void RenderSized(int width, int height, std::vector<uint8_t>* rgb) const override {
    env_->RenderSized(width, height, rgb);
  }

  /// The wrapped env (Gymnasium's `env.env`).
  Inner& wrapped_env() { return *env_; }
  const Inner& wrapped_env() const { return *env_; }

 protected:
  /// Takes ownership of `env`; throws std::invalid_argument("<name>: the wrapped env must not be
  /// null") if it is null.
  EnvWrapper(std::unique_ptr<Inner> env, const char* name)
      : Base(NotNull(env, name).spec()), env_(std::move(env)) {}

  /// Resets the wrapped env with the same seed (or none).
  void OnReset(std::optional<uint64_t> seed) override {
    if (seed.has_value()) {
      env_->Reset(*seed);
    } else {
      env_->Reset();
    }
  }

  std::unique_ptr<Inner> env_;

 private:
  static const Inner& NotNull(const std::unique_ptr<Inner>& env, const char* name) {
    if (env == nullptr) {
      throw std::invalid_argument(std::string(name) + ": the wrapped env must not be null");
    }
    return *env;
  }
};

}  // namespace rl::envs
