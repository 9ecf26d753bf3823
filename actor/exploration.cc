#include "actor/exploration.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rl::actor {

double ApexEpsilon(int actor_index, int num_actors, double base, double alpha) {
  if (num_actors <= 1) return base;
  const double exponent =
      1.0 + alpha * static_cast<double>(actor_index) / static_cast<double>(num_actors - 1);
  return std::pow(base, exponent);
}

double LinearEpsilon(int64_t step, double start, double end, int64_t anneal_steps) {
  if (anneal_steps <= 0 || step >= anneal_steps) return end;
  const double frac = static_cast<double>(step) / static_cast<double>(anneal_steps);
  return start + (end - start) * frac;
}

void ExplorationConfig::Validate() const {
  if (mode != "apex" && mode != "linear" && mode != "constant" && mode != "gaussian") {
    throw std::invalid_argument(
        "exploration must be apex, linear, constant (epsilon-greedy) or gaussian (noise), not '" +
        mode + "'");
  }
  if (!(sigma >= 0 && sigma_end >= 0 && std::isfinite(sigma) && std::isfinite(sigma_end))) {
    throw std::invalid_argument("noise sigma must be finite and >= 0");
  }
  if (!(noise_spread > 0 && noise_spread <= 1)) {
    throw std::invalid_argument("noise-spread must be in (0, 1]");
  }
  if (sigma_anneal_steps < 0) throw std::invalid_argument("sigma-anneal-steps must be >= 0");
  if (start_steps < 0) throw std::invalid_argument("start-steps must be >= 0");
  for (double e : {apex_base, start, end}) {
    if (!(e >= 0.0 && e <= 1.0)) throw std::invalid_argument("epsilon must be in [0, 1]");
  }
  if (apex_alpha < 0) throw std::invalid_argument("apex alpha must be >= 0");
}

double ExplorationConfig::Epsilon(int actor_index, int num_actors, int64_t step) const {
  if (mode == "apex") return ApexEpsilon(actor_index, num_actors, apex_base, apex_alpha);
  if (mode == "linear") return LinearEpsilon(step, start, end, anneal_steps);
  return end;
}

double ExplorationConfig::Sigma(int actor_index, int num_actors, int64_t step) const {
  const double scale = num_actors <= 1
                           ? 1.0
                           : std::pow(noise_spread, static_cast<double>(actor_index) /
                                                        static_cast<double>(num_actors - 1));
  if (sigma_anneal_steps == 0) return scale * sigma;
  return scale * LinearEpsilon(step, sigma, sigma_end, sigma_anneal_steps);
}

}  // namespace rl::actor
