// The report's t-SNE map of a pixel policy, as in Mnih et al. 2015, Figure 4: states of greedy
// episodes, placed by a 2-D t-SNE embedding (tsne.h) of what the network's last hidden layer makes
// of them, coloured by the value of the state, with a few of their frames beside their points.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "evaluator/scorer.h"
#include "evaluator/tsne.h"
#include "nn/sequential.h"
#include "nn/tensor.h"

namespace rl::evaluator {

/// Bounds of the number of states of a map (the embedding is O(N^2) in time and memory).
inline constexpr int kTsneMapMinStates = 100;
inline constexpr int kTsneMapMaxStates = 5000;
/// Frames shown beside their points.
inline constexpr int kTsneMapThumbnails = 5;

/// Index of the layer whose input is the network's last hidden layer: the last Linear layer, or
/// the last Dueling head (whose input is what both of its streams read). Throws
/// std::invalid_argument when the network has neither, or when that layer is its first (no
/// hidden layer).
int LastHiddenLayerIndex(const nn::Sequential& net);

/// States of greedy episodes and what the network made of them; state i is column i.
struct StateSamples {
  nn::Matrix activations;  // D x N: the input of layer `layer` (LastHiddenLayerIndex) in state i
  std::vector<double> values;  // N: the value of state i (see value_is_return)
  // True when values are the discounted returns that followed the states (a network without
  // value estimates: a TD3 actor), false when they are the network's max_a Q(s, a).
  bool value_is_return = false;
  std::vector<uint8_t> frames;  // N x frame_height x frame_width: the newest frame of state i
  int frame_height = 0, frame_width = 0;
  int episodes = 0;  // greedy episodes played (episode e reset with seed first_seed + e)
  int layer = 0;     // the layer whose input the activations are
  std::string layer_description;  // its Describe(), e.g. "dueling(800,64,3)"
};

/// Plays greedy episodes of `env_id` with `net` (epsilon 0 or no noise; episode e reset with seed
/// first_seed + e; at most `states` episodes) until `states` states are collected, recording for
/// each state before its action the activations of the last hidden layer (read with
/// Sequential::LayerInput, no extra pass), the newest frame and the value: max_a Q(s, a) for a
/// Q-network; for a network without value estimates (a TD3 actor) the discounted return
/// (discount `gamma`) that followed the state in its episode, up to the episode's end or its time
/// limit (what lies beyond a time limit is unseen: such returns are short of the truth near the
/// cut). `after_step` (when set) is called after every step with the states collected so far;
/// what it throws propagates (a caller's way to stop). Throws std::invalid_argument for
/// states outside [kTsneMapMinStates, kTsneMapMaxStates], gamma outside [0, 1], an env without
/// frames, or a network that does not fit the env or has no hidden layer. Memory: N x (D floats +
/// one frame), plus one episode's worth for a network without value estimates.
StateSamples CollectStates(nn::Sequential* net, const std::string& env_id, int states,
                           uint64_t first_seed = kDefaultEvalSeedBase, double gamma = kDefaultGamma,
                           const std::function<void(int states)>& after_step = {});

/// Which states get a thumbnail: up to `count` (>= 1) states at evenly spaced quantiles of the
/// value, lowest and highest included, preferring states whose frames differ from those already
/// chosen; sorted by value, no index twice. Empty for no values.
std::vector<int> ThumbnailStates(const StateSamples& samples, int count);

/// The distinct states of `samples`: states with identical activations (the same bytes) merged
/// into one, in the order of their first occurrence, with that state's frame and the mean of their
/// values; *counts (when not null) receives how many states each one stands for. A small env
/// such as Catch repeats its few states many times, and t-SNE gives copies of a point all of its
/// neighbourhood, which would leave the map without links between different states. Throws
/// std::invalid_argument when the samples are inconsistent. O(N D) expected.
StateSamples DistinctStates(const StateSamples& samples, std::vector<int>* counts = nullptr);

/// What WriteTsneMap drew.
struct TsneMapResult {
  int states = 0;    // samples
  int distinct = 0;  // distinct states (DistinctStates): the points of the map
  int episodes = 0;
  int features = 0;       // D
  double perplexity = 0;  // the one used: the config's, or (distinct - 1) / 3 if that is smaller
  double kl_divergence = 0;
  double value_min = 0, value_max = 0;  // of the distinct states
  std::vector<int> thumbnails;          // ThumbnailStates() of the distinct states
  int width = 0, height = 0;            // of the PNG
};

/// Embeds the distinct states of `samples` (DistinctStates) with t-SNE (`config`, with the
/// perplexity lowered to (distinct - 1) / 3 when there are too few of them; `progress` as in
/// Tsne, every 50 iterations) and writes the map to `path` as PNG, atomically: a scatter plot of
/// the states coloured by value (viridis: low dark blue, high yellow; a state seen k times is a
/// disc of up to 9 times the area) with a colour bar, and kTsneMapThumbnails of their frames
/// (scaled up by pixel replication) beside the plot, each joined to its point by a thin line and
/// labelled with its value. Throws what Tsne() throws, std::invalid_argument when the samples are
/// inconsistent, have no frames or a value that is not finite, std::runtime_error when there are
/// fewer than kTsneMinPoints distinct states or the PNG cannot be encoded or written.
TsneMapResult WriteTsneMap(const StateSamples& samples, const TsneConfig& config,
                           const std::string& path,
                           const std::function<void(const TsneProgress&)>& progress = {});

}  // namespace rl::evaluator
