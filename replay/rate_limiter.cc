#include "replay/rate_limiter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace rl::replay {
namespace {

// Shortest readable form of a number, for error messages ("8", "0.5", "1e+20").
std::string Str(double x) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", x);
  return buf;
}

}  // namespace

void RateLimiterOptions::Validate() const {
  if (!std::isfinite(samples_per_insert)) {
    throw std::invalid_argument("rate limiter: samples_per_insert must be finite");
  }
  if (min_size_to_sample < 1) {
    throw std::invalid_argument("rate limiter: min_size_to_sample must be at least 1, got " +
                                std::to_string(min_size_to_sample));
  }
  if (!std::isfinite(error_buffer) || error_buffer < 0) {
    throw std::invalid_argument("rate limiter: error_buffer must be finite and >= 0, got " +
                                Str(error_buffer));
  }
  if (samples_per_insert > 0 && error_buffer < std::max(1.0, samples_per_insert)) {
    throw std::invalid_argument(
        "rate limiter: error_buffer must be at least max(1, samples_per_insert) = " +
        Str(std::max(1.0, samples_per_insert)) + ", got " + Str(error_buffer) +
        " (a smaller one can block inserts or samples for good)");
  }
}

RateLimiter::RateLimiter(RateLimiterOptions options) : options_(options) { options_.Validate(); }

double RateLimiter::diff() const {
  return static_cast<double>(inserts_) * options_.samples_per_insert -
         static_cast<double>(samples_);
}

double RateLimiter::min_diff() const {
  return options_.samples_per_insert * static_cast<double>(options_.min_size_to_sample) -
         options_.error_buffer;
}

double RateLimiter::max_diff() const {
  return options_.samples_per_insert * static_cast<double>(options_.min_size_to_sample) +
         options_.error_buffer;
}

bool RateLimiter::CanInsert(int64_t n) const {
  if (!enabled() || inserts_ < options_.min_size_to_sample) return true;
  return diff() + static_cast<double>(n) * options_.samples_per_insert <= max_diff();
}

bool RateLimiter::CanSample(int64_t n) const {
  if (inserts_ < options_.min_size_to_sample) return false;
  if (!enabled()) return true;
  return diff() - static_cast<double>(n) >= min_diff();
}

int64_t RateLimiter::InsertCredit() const {
  if (!enabled()) return -1;
  const double room = (max_diff() - diff()) / options_.samples_per_insert;
  // Below min_size every insert is allowed, whatever the ratio says.
  const double before_min = static_cast<double>(options_.min_size_to_sample - inserts_);
  return static_cast<int64_t>(std::floor(std::max({0.0, room, before_min})));
}

void RateLimiter::Restore(int64_t inserts, int64_t samples) {
  if (inserts < 0 || samples < 0) {
    throw std::invalid_argument("rate limiter: counts must be >= 0, got " +
                                std::to_string(inserts) + " inserts and " +
                                std::to_string(samples) + " samples");
  }
  inserts_ = inserts;
  samples_ = samples;
}

int64_t RateLimiter::max_sample_batch() const {
  if (!enabled()) return 0;
  return static_cast<int64_t>(
      std::floor(2.0 * options_.error_buffer - options_.samples_per_insert));
}

double RateLimiter::samples_per_insert() const {
  const int64_t since = inserts_ - options_.min_size_to_sample;
  return since > 0 ? static_cast<double>(samples_) / static_cast<double>(since) : 0.0;
}

}  // namespace rl::replay
