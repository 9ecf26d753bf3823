// Helpers of Algorithm::SaveState/LoadState: networks (their architecture string and flat
// parameters), optimizer states and random generators as StateFile sections.
#pragma once

#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/state_file.h"
#include "nn/optimizers.h"

namespace rl::learner {

/// Sections "<name>.arch" and "<name>" for a network with Architecture(), GetFlat(), SetFlat()
/// (nn::Sequential, nn::ActionValueNet).
template <class Net>
void PutNet(StateFile* state, const std::string& name, const Net& net) {
  std::vector<float> flat;
  net.GetFlat(&flat);
  state->PutText(name + ".arch", net.Architecture());
  state->PutFloats(name, flat);
}

/// Restores PutNet's sections into `net`, which must have the same architecture.
template <class Net>
void GetNet(const StateFile& state, const std::string& name, Net* net) {
  if (state.Text(name + ".arch") != net->Architecture()) {
    throw std::runtime_error("state network '" + name +
                             "' has another architecture: " + state.Text(name + ".arch"));
  }
  const auto flat = state.Floats(name, net->FlatSize());
  net->SetFlat(flat.data(), flat.size());
}

/// Sections "<name>" (the per-parameter buffers) and "<name>.steps".
inline void PutOptimizer(StateFile* state, const std::string& name, const nn::Optimizer& opt) {
  std::vector<float> values;
  int64_t steps = 0;
  opt.GetState(&values, &steps);
  state->PutFloats(name, values);
  state->PutInt(name + ".steps", steps);
}

inline void GetOptimizer(const StateFile& state, const std::string& name, nn::Optimizer* opt) {
  try {
    opt->SetState(state.Floats(name), state.Int(name + ".steps"));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("state optimizer '" + name + "': " + e.what());
  }
}

/// A standard generator or distribution, through its textual state (operator<< and >>).
template <class Engine>
void PutRng(StateFile* state, const std::string& name, const Engine& engine) {
  std::ostringstream out;
  out << engine;
  state->PutText(name, out.str());
}

template <class Engine>
void GetRng(const StateFile& state, const std::string& name, Engine* engine) {
  std::istringstream in(state.Text(name));
  in >> *engine;
  if (!in) throw std::runtime_error("state generator '" + name + "' does not parse");
}

}  // namespace rl::learner
