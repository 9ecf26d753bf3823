#include "envs/rng.h"

#include "common/check.h"

namespace rl::envs {

void SeedRng(uint64_t seed, std::mt19937_64& rng) {
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
  rng.seed(seq);
}

void SeedRngRandomly(std::mt19937_64& rng) {
  std::random_device device;
  std::seed_seq seq{device(), device(), device(), device()};
  rng.seed(seq);
}

double UniformDouble(std::mt19937_64& rng, double low, double high) {
  const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
  return low + (high - low) * u;
}

int64_t UniformInt(std::mt19937_64& rng, int64_t low, int64_t high) {
  RL_CHECK(low < high) << "UniformInt needs low < high, got [" << low << ", " << high << ")";
  const uint64_t range = static_cast<uint64_t>(high) - static_cast<uint64_t>(low);
  // Draws in [2^64 mod range, 2^64) are a whole number of copies of [0, range), so reducing an
  // accepted draw modulo range is unbiased. Fewer than half of the draws are rejected.
  const uint64_t rejected_below = (0 - range) % range;
  while (true) {
    const uint64_t draw = rng();
    if (draw >= rejected_below) {
      return static_cast<int64_t>(static_cast<uint64_t>(low) + draw % range);
    }
  }
}

void EnvRng::Seed(uint64_t seed) {
  SeedRng(seed, *this);
  seeded_ = true;
}

void EnvRng::SeedIfUnseeded() {
  if (!seeded_) SeedRngRandomly(*this);
  seeded_ = true;
}

}  // namespace rl::envs
