// RateLimiter keeps the ratio between transitions sampled and transitions inserted close to a
// target, samples_per_insert (SPI), once the table holds min_size_to_sample transitions. It
// follows the semantics of Reverb's rate limiter; counts are in transitions (a sampled batch of
// 128 counts as 128 samples, an inserted batch of 32 as 32 inserts).
//
// With diff = inserts * SPI - samples:
//   min_diff = SPI * min_size_to_sample - error_buffer
//   max_diff = SPI * min_size_to_sample + error_buffer
//   CanInsert(n): inserts < min_size_to_sample, or diff + n * SPI <= max_diff
//   CanSample(n): inserts >= min_size_to_sample, and diff - n >= min_diff
// so after the warm-up the inserters may run at most error_buffer / SPI transitions ahead of
// the target ratio, and the samplers at most error_buffer samples ahead. With SPI <= 0 the ratio
// is not enforced: inserts are always allowed and samples once min_size_to_sample transitions
// have been inserted.
//
// The limiter only answers and counts; it never blocks and never waits. Whoever asks decides
// what to do with a "no" (the replay daemon holds sample requests and tells actors to pause, but
// stores every transition that still arrives; diff may then exceed max_diff for a while).
//
// Deadlock freedom: when inserts are refused, a sample of n must be possible, and the other way
// round. That holds for every n <= max_sample_batch() = 2 * error_buffer - SPI (for an insert
// unit of 1 transition); larger sample batches can wait forever, so callers should refuse them.
//
// Not thread-safe: one thread calls every method.
#pragma once

#include <cstdint>

namespace rl::replay {

struct RateLimiterOptions {
  // Target transitions sampled per transition inserted; <= 0 disables the ratio (only
  // min_size_to_sample applies).
  double samples_per_insert = 8.0;
  // Transitions that must have been inserted before the first sample.
  int64_t min_size_to_sample = 1000;
  // Tolerated deviation of diff from its target, in samples. With SPI > 0 it must be at least
  // max(1, SPI), or a single insert or sample could be blocked for good.
  double error_buffer = 2000.0;

  /// Throws std::invalid_argument naming the field when a value is out of range.
  void Validate() const;
};

class RateLimiter {
 public:
  /// Throws std::invalid_argument when the options are bad.
  explicit RateLimiter(RateLimiterOptions options);

  /// Whether inserting n more transitions keeps the ratio within bounds. O(1).
  bool CanInsert(int64_t n) const;
  /// Whether sampling n more transitions keeps the ratio within bounds. O(1).
  bool CanSample(int64_t n) const;

  /// How many more transitions CanInsert admits now, one at a time: the largest n such that
  /// inserting n transitions one by one keeps CanInsert(1) true before each (at least the
  /// transitions missing to min_size_to_sample); -1 when the ratio is not enforced. The replay
  /// shares it out among the actors (flow_control_t), so that they stop in time even while
  /// their transitions are still on the way. O(1).
  int64_t InsertCredit() const;
  /// Records n transitions inserted (allowed or not).
  void Insert(int64_t n) { inserts_ += n; }
  /// Records n transitions sampled (allowed or not).
  void Sample(int64_t n) { samples_ += n; }
  /// Sets both counts (from a snapshot); throws std::invalid_argument when one is negative.
  void Restore(int64_t inserts, int64_t samples);

  /// Largest sample batch that can never deadlock (see the file comment); 0 when SPI <= 0 (no
  /// limit).
  int64_t max_sample_batch() const;

  int64_t inserts() const { return inserts_; }
  int64_t samples() const { return samples_; }
  /// inserts * SPI - samples.
  double diff() const;
  double min_diff() const;
  double max_diff() const;
  /// Samples per insert since sampling became possible: samples / (inserts - min_size), or 0
  /// before any insert beyond min_size.
  double samples_per_insert() const;
  const RateLimiterOptions& options() const { return options_; }

 private:
  bool enabled() const { return options_.samples_per_insert > 0; }

  RateLimiterOptions options_;
  int64_t inserts_ = 0;
  int64_t samples_ = 0;
};

}  // namespace rl::replay
