// The learner's algorithms: this file is the one list of them. Adding an algorithm is its own
// header and source (learner/*.cc are built by a glob), its #include here and its config in
// AlgorithmConfigs; the learner, its command line, its INI section and its checks follow.
//
// What every algorithm's config provides (DqnConfig and Td3Config are the examples):
//   kName, kSummary        its --algorithm value and a line for --help;
//   network, hidden, tau, adam_eps, max_grad_norm, seed, precision
//                          the settings every algorithm has (with defaults of its own; the
//                          command line sets them on the chosen algorithm only);
//   Validate()             throws std::invalid_argument naming a bad field;
//   AddOptions(desc)       adds its own options, bound to its fields (an option two algorithms
//                          share belongs in learner/main.cc with the settings above);
//   Make(spec)             builds the algorithm for an env (throws std::invalid_argument when the
//                          env's actions do not fit it).
#pragma once

#include <stdexcept>
#include <string>
#include <tuple>

#include "learner/dqn.h"
#include "learner/td3.h"

namespace rl::learner {

// Every algorithm's config, in the order --help lists them; the first is the default.
using AlgorithmConfigs = std::tuple<DqnConfig, Td3Config>;

/// Calls f(config) on each algorithm's config in turn.
template <class Configs, class F>
void ForEachAlgorithm(Configs&& configs, F&& f) {
  std::apply([&](auto&... config) { (f(config), ...); }, configs);
}

/// "dqn, td3": the known names, for errors and help.
inline std::string AlgorithmNames() {
  std::string names;
  ForEachAlgorithm(AlgorithmConfigs{}, [&](const auto& config) {
    names += (names.empty() ? "" : ", ") + std::string(config.kName);
  });
  return names;
}

/// Throws std::invalid_argument("algorithm must be one of dqn, td3, not '<name>'") unless `name`
/// is an algorithm's kName.
inline void CheckAlgorithmName(const std::string& name) {
  bool known = false;
  ForEachAlgorithm(AlgorithmConfigs{}, [&](const auto& config) { known |= name == config.kName; });
  if (!known) {
    throw std::invalid_argument("algorithm must be one of " + AlgorithmNames() + ", not '" + name +
                                "'");
  }
}

}  // namespace rl::learner
