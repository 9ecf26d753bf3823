// Seeding and sampling helpers shared by the environments. Every env instance owns one
// std::mt19937_64; these functions fix how it is seeded and how numbers are drawn from it, so that
// the streams do not depend on the standard library's distribution classes.
#pragma once

#include <cstdint>
#include <random>

namespace rl::envs {

/// Seeds `rng` through std::seed_seq from the two 32-bit halves of `seed`.
void SeedRng(uint64_t seed, std::mt19937_64& rng);

/// Seeds `rng` from std::random_device (for a Reset() that comes before any seeded Reset).
void SeedRngRandomly(std::mt19937_64& rng);

/// The RNG an env owns, with Gymnasium's seeding rule: Reset(seed) seeds it (Seed), and a Reset()
/// without a seed continues its stream, seeded from std::random_device first if it never was
/// (SeedIfUnseeded). It is the generator itself, so it goes wherever a std::mt19937_64 does.
/// Copies continue the same stream.
class EnvRng : public std::mt19937_64 {
 public:
  /// SeedRng(seed, *this).
  void Seed(uint64_t seed);
  /// SeedRngRandomly(*this) unless Seed or SeedIfUnseeded came before.
  void SeedIfUnseeded();

 private:
  bool seeded_ = false;
};

/// A double uniform in [low, high) from 53 random bits, as numpy's Generator.uniform computes it:
/// low + (high - low) * u with u = (bits >> 11) * 2^-53. One draw.
double UniformDouble(std::mt19937_64& rng, double low, double high);

/// An integer uniform in [low, high) (high exclusive, like numpy's Generator.integers), without
/// modulo bias (rejection sampling). Requires low < high. One or more draws.
int64_t UniformInt(std::mt19937_64& rng, int64_t low, int64_t high);

}  // namespace rl::envs
