#include "evaluator/tsne_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "envs/registry.h"
#include "evaluator/learning_curve.h"
#include "nn/dueling.h"
#include "nn/linear.h"

namespace rl::evaluator {

int LastHiddenLayerIndex(const nn::Sequential& net) {
  for (int i = net.num_layers() - 1; i >= 0; --i) {
    const nn::Layer& layer = net.layer(i);
    if (dynamic_cast<const nn::Linear*>(&layer) == nullptr &&
        dynamic_cast<const nn::Dueling*>(&layer) == nullptr) {
      continue;
    }
    if (i == 0) {
      throw std::invalid_argument("network " + net.Architecture() +
                                  " has no hidden layer before its last linear layer");
    }
    return i;
  }
  throw std::invalid_argument("network " + net.Architecture() +
                              " has no linear layer or dueling head");
}

StateSamples CollectStates(nn::Sequential* net, const std::string& env_id, int states,
                           uint64_t first_seed, double gamma,
                           const std::function<void(int states)>& after_episode) {
  if (states < kTsneMapMinStates || states > kTsneMapMaxStates) {
    throw std::invalid_argument("a t-SNE map needs " + std::to_string(kTsneMapMinStates) + " to " +
                                std::to_string(kTsneMapMaxStates) + " states, got " +
                                std::to_string(states));
  }
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    throw std::invalid_argument("gamma must be in [0, 1], got " + std::to_string(gamma));
  }
  const std::unique_ptr<envs::Env> env = envs::MakeEnv(env_id);
  const envs::EnvSpec& spec = env->spec();
  if (spec.frame_height <= 0) {
    throw std::invalid_argument(env_id + " has no camera frames (not a pixel env)");
  }
  // The greedy policy (epsilon 0; no noise): throws when the network does not fit the env.
  const std::unique_ptr<actor::Policy> policy = EvaluationPolicy(*net, spec, 0.0, first_seed);
  nn::Sequential& policy_net = policy->network();
  StateSamples s;
  s.layer = LastHiddenLayerIndex(policy_net);
  s.layer_description = policy_net.layer(s.layer).Describe();
  s.frame_height = spec.frame_height;
  s.frame_width = spec.frame_width;
  const int features = policy_net.layer(s.layer).input_size();
  const size_t frame_bytes = static_cast<size_t>(spec.frame_height) * spec.frame_width;
  s.activations.resize(features, states);
  s.values.reserve(static_cast<size_t>(states));
  s.frames.reserve(static_cast<size_t>(states) * frame_bytes);
  std::vector<float> action(static_cast<size_t>(spec.action_width()));

  // A network without value estimates gets the returns: its states wait for the episode's end.
  std::vector<float> episode_activations;
  std::vector<uint8_t> episode_frames;
  std::vector<double> episode_rewards;
  int n = 0;
  auto keep = [&](const float* activation, const uint8_t* frame, double value) {
    std::copy_n(activation, features, s.activations.col(n).data());
    s.frames.insert(s.frames.end(), frame, frame + frame_bytes);
    s.values.push_back(value);
    ++n;
  };
  for (int e = 0; e < states && n < states; ++e) {
    env->Reset(first_seed + static_cast<uint64_t>(e));
    episode_activations.clear();
    episode_frames.clear();
    episode_rewards.clear();
    for (;;) {
      policy->Act(env->observation(), 0, action);
      const nn::Matrix& hidden = policy_net.LayerInput(s.layer);
      const std::span<const uint8_t> frame = env->frame();
      if (hidden.rows() != features || frame.size() != frame_bytes) {
        throw std::logic_error("hidden layer or frame of an unexpected size");
      }
      const std::optional<double> value = policy->last_value();
      if (e == 0 && episode_rewards.empty()) s.value_is_return = !value.has_value();
      if (!s.value_is_return) {
        keep(hidden.data(), frame.data(), *value);  // greedy: Q of the argmax, max_a Q(s, a)
      } else {
        episode_activations.insert(episode_activations.end(), hidden.data(),
                                   hidden.data() + features);
        episode_frames.insert(episode_frames.end(), frame.begin(), frame.end());
      }
      const envs::StepResult step = env->Act(action);
      episode_rewards.push_back(step.reward);
      const bool done = step.terminated || step.truncated;
      if (s.value_is_return && done) {
        // The discounted return from every step to the episode's end (or its time limit).
        const size_t steps = episode_rewards.size();
        std::vector<double> returns(steps);
        double g = 0;
        for (size_t t = steps; t-- > 0;) {
          g = episode_rewards[t] + gamma * g;
          returns[t] = g;
        }
        for (size_t t = 0; t < steps && n < states; ++t) {
          keep(episode_activations.data() + t * static_cast<size_t>(features),
               episode_frames.data() + t * frame_bytes, returns[t]);
        }
      }
      if (done || (!s.value_is_return && n == states)) break;
    }
    ++s.episodes;
    if (after_episode) after_episode(n);
  }
  if (n < states) {
    throw std::logic_error("only " + std::to_string(n) + " of " + std::to_string(states) +
                           " states in " + std::to_string(s.episodes) + " episodes");
  }
  return s;
}

std::vector<int> ThumbnailStates(const StateSamples& samples, int count) {
  const int n = static_cast<int>(samples.values.size());
  if (count < 1) throw std::invalid_argument("ThumbnailStates needs a count of at least 1");
  if (n == 0) return {};
  count = std::min(count, n);
  std::vector<int> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return samples.values[static_cast<size_t>(a)] < samples.values[static_cast<size_t>(b)];
  });
  const size_t frame_bytes = static_cast<size_t>(samples.frame_height) * samples.frame_width;
  const bool has_frames = frame_bytes > 0 && samples.frames.size() == frame_bytes * n;
  auto frame = [&](int i) {
    return samples.frames.begin() + static_cast<ptrdiff_t>(frame_bytes * i);
  };
  std::vector<int> chosen;
  auto taken = [&](int i) { return std::find(chosen.begin(), chosen.end(), i) != chosen.end(); };
  auto fresh = [&](int i) {
    if (taken(i)) return false;
    if (!has_frames) return true;
    return std::none_of(chosen.begin(), chosen.end(), [&](int c) {
      return std::equal(frame(i), frame(i) + static_cast<ptrdiff_t>(frame_bytes), frame(c));
    });
  };
  // Look this far (in value order) around each quantile for a frame not shown yet.
  const int window = std::max(1, n / (2 * count));
  for (int k = 0; k < count; ++k) {
    const double q = count == 1 ? 0.5 : static_cast<double>(k) / (count - 1);
    const int pos = static_cast<int>(std::lround(q * (n - 1)));
    int pick = -1;
    for (int off = 0; off <= window && pick < 0; ++off) {
      for (int sign : {1, -1}) {
        const int p = pos + sign * off;
        if (p >= 0 && p < n && fresh(order[static_cast<size_t>(p)])) {
          pick = order[static_cast<size_t>(p)];
          break;
        }
      }
    }
    // All frames near the quantile shown already: the nearest state not chosen yet.
    for (int off = 0; pick < 0 && off < n; ++off) {
      for (int sign : {1, -1}) {
        const int p = pos + sign * off;
        if (p >= 0 && p < n && !taken(order[static_cast<size_t>(p)])) {
          pick = order[static_cast<size_t>(p)];
          break;
        }
      }
    }
    chosen.push_back(pick);
  }
  std::stable_sort(chosen.begin(), chosen.end(), [&](int a, int b) {
    return samples.values[static_cast<size_t>(a)] < samples.values[static_cast<size_t>(b)];
  });
  return chosen;
}

namespace {

// Layout of the picture, in pixels.
constexpr int kPlotSide = 560;  // the square scatter plot
constexpr int kMargin = 16;
constexpr int kTitleHeight = 34;
constexpr int kColumnGap = 36;      // between a column of thumbnails and the plot
constexpr int kThumbSide = 96;      // the longer side of a thumbnail
constexpr int kLabelHeight = 18;    // below a thumbnail
constexpr int kBarWidth = 16;       // the colour bar
constexpr int kBarLabels = 64;      // room for its tick labels
constexpr double kFont = 0.45;      // FONT_HERSHEY_SIMPLEX scale
const cv::Scalar kInk(40, 40, 40);  // BGR
const cv::Scalar kLine(110, 110, 110);

// The viridis colour map, 256 BGR entries.
std::vector<cv::Vec3b> Viridis() {
  cv::Mat ramp(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
  cv::Mat colours;
  cv::applyColorMap(ramp, colours, cv::COLORMAP_VIRIDIS);
  std::vector<cv::Vec3b> lut(256);
  for (int i = 0; i < 256; ++i) lut[static_cast<size_t>(i)] = colours.at<cv::Vec3b>(0, i);
  return lut;
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

}  // namespace

StateSamples DistinctStates(const StateSamples& samples, std::vector<int>* counts) {
  const auto n = static_cast<int>(samples.activations.cols());
  const auto features = static_cast<size_t>(samples.activations.rows());
  const size_t frame_bytes = static_cast<size_t>(samples.frame_height) * samples.frame_width;
  if (samples.values.size() != static_cast<size_t>(n) ||
      samples.frames.size() != frame_bytes * static_cast<size_t>(n)) {
    throw std::invalid_argument("state samples: " + std::to_string(n) + " states, " +
                                std::to_string(samples.values.size()) + " values and " +
                                std::to_string(samples.frames.size()) + " frame bytes");
  }
  // Groups of identical activation vectors (the same bytes), found by hashing, in the order of
  // their first states.
  auto bytes = [&](int i) {
    return std::string_view(reinterpret_cast<const char*>(samples.activations.col(i).data()),
                            features * sizeof(float));
  };
  std::unordered_multimap<size_t, int> seen;  // hash -> group
  std::vector<int> first;                     // per group: its first state
  std::vector<double> sums;
  std::vector<int> sizes;
  for (int i = 0; i < n; ++i) {
    const size_t h = std::hash<std::string_view>()(bytes(i));
    int group = -1;
    const auto [begin, end] = seen.equal_range(h);
    for (auto it = begin; it != end && group < 0; ++it) {
      if (bytes(first[static_cast<size_t>(it->second)]) == bytes(i)) group = it->second;
    }
    if (group < 0) {
      group = static_cast<int>(first.size());
      seen.emplace(h, group);
      first.push_back(i);
      sums.push_back(0);
      sizes.push_back(0);
    }
    sums[static_cast<size_t>(group)] += samples.values[static_cast<size_t>(i)];
    ++sizes[static_cast<size_t>(group)];
  }
  StateSamples d;
  const auto groups = static_cast<int>(first.size());
  d.activations.resize(samples.activations.rows(), groups);
  d.frames.resize(frame_bytes * static_cast<size_t>(groups));
  for (int g = 0; g < groups; ++g) {
    const int i = first[static_cast<size_t>(g)];
    d.activations.col(g) = samples.activations.col(i);
    std::copy_n(samples.frames.begin() + static_cast<ptrdiff_t>(frame_bytes * i), frame_bytes,
                d.frames.begin() + static_cast<ptrdiff_t>(frame_bytes * g));
    d.values.push_back(sums[static_cast<size_t>(g)] / sizes[static_cast<size_t>(g)]);
  }
  d.value_is_return = samples.value_is_return;
  d.frame_height = samples.frame_height;
  d.frame_width = samples.frame_width;
  d.episodes = samples.episodes;
  d.layer = samples.layer;
  d.layer_description = samples.layer_description;
  if (counts != nullptr) *counts = std::move(sizes);
  return d;
}

TsneMapResult WriteTsneMap(const StateSamples& all, const TsneConfig& config,
                           const std::string& path,
                           const std::function<void(const TsneProgress&)>& progress) {
  if (all.frame_height <= 0 || all.frame_width <= 0) {
    throw std::invalid_argument("t-SNE map: states without frames");
  }
  for (size_t i = 0; i < all.values.size(); ++i) {
    if (!std::isfinite(all.values[i])) {
      throw std::invalid_argument("t-SNE map: the value of state " + std::to_string(i) +
                                  " is not finite");
    }
  }
  std::vector<int> counts;
  const StateSamples samples = DistinctStates(all, &counts);
  const auto n = static_cast<int>(samples.activations.cols());
  const size_t frame_bytes = static_cast<size_t>(samples.frame_height) * samples.frame_width;
  if (n < kTsneMinPoints) {
    throw std::runtime_error("t-SNE map: only " + std::to_string(n) + " distinct states of " +
                             std::to_string(all.activations.cols()) +
                             " (the network gives almost every state the same activations)");
  }
  TsneMapResult result;
  result.states = static_cast<int>(all.activations.cols());
  result.distinct = n;
  result.episodes = samples.episodes;
  result.features = static_cast<int>(samples.activations.rows());
  // Fewer distinct states than the perplexity needs: as many neighbours as they allow.
  TsneConfig tsne = config;
  tsne.perplexity = std::min(config.perplexity, std::max(1.0, (n - 1) / 3.0));
  result.perplexity = tsne.perplexity;
  const Eigen::MatrixXd y = Tsne(samples.activations, tsne, progress, 50, &result.kl_divergence);

  // Colours by value.
  const auto [lo_it, hi_it] = std::minmax_element(samples.values.begin(), samples.values.end());
  result.value_min = *lo_it;
  result.value_max = *hi_it;
  double lo = result.value_min, hi = result.value_max;
  if (!(hi > lo)) {  // one value: the middle colour
    lo -= 0.5;
    hi += 0.5;
  }
  const std::vector<cv::Vec3b> lut = Viridis();
  auto colour = [&](double v) {
    const int k = static_cast<int>(std::lround(std::clamp((v - lo) / (hi - lo), 0.0, 1.0) * 255));
    const cv::Vec3b c = lut[static_cast<size_t>(k)];
    return cv::Scalar(c[0], c[1], c[2]);
  };

  // Thumbnails: frames scaled up by an integer factor to at most kThumbSide.
  const int scale = std::max(1, kThumbSide / std::max(samples.frame_height, samples.frame_width));
  const int thumb_w = samples.frame_width * scale;
  const int thumb_h = samples.frame_height * scale;
  result.thumbnails = ThumbnailStates(samples, kTsneMapThumbnails);

  // The page.
  const int plot_x = kMargin + thumb_w + kColumnGap;
  const int plot_y = kTitleHeight;
  const int right_x = plot_x + kPlotSide + kColumnGap;
  const int bar_x = right_x + thumb_w + kColumnGap;
  const int width = bar_x + kBarWidth + kBarLabels;
  const int height = plot_y + kPlotSide + kMargin;
  cv::Mat page(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  // The title, shrunk to end before the colour bar's label.
  const std::string title =
      "t-SNE of the last hidden layer (" + std::to_string(result.features) +
      " features): " + std::to_string(result.states) + " states" +
      (n < result.states ? " (" + std::to_string(n) + " distinct)" : std::string()) + ", by " +
      (samples.value_is_return ? "return" : "value");
  double title_scale = 0.55;
  int baseline = 0;
  while (title_scale > 0.3 &&
         cv::getTextSize(title, cv::FONT_HERSHEY_SIMPLEX, title_scale, 1, &baseline).width >
             bar_x - kColumnGap / 2 - kMargin) {
    title_scale -= 0.05;
  }
  cv::putText(page, title, cv::Point(kMargin, 22), cv::FONT_HERSHEY_SIMPLEX, title_scale, kInk, 1,
              cv::LINE_AA);
  cv::rectangle(page, cv::Rect(plot_x, plot_y, kPlotSide, kPlotSide), cv::Scalar(210, 210, 210), 1);

  // Embedding to pixels: one scale for both axes (t-SNE distances are isotropic), centred, y up.
  const double x_min = y.row(0).minCoeff(), x_max = y.row(0).maxCoeff();
  const double y_min = y.row(1).minCoeff(), y_max = y.row(1).maxCoeff();
  const double span = std::max({x_max - x_min, y_max - y_min, 1e-12});
  const double pixels = (kPlotSide - 24) / span;
  auto to_pixel = [&](int i) {
    const double px = plot_x + kPlotSide / 2.0 + (y(0, i) - (x_min + x_max) / 2) * pixels;
    const double py = plot_y + kPlotSide / 2.0 - (y(1, i) - (y_min + y_max) / 2) * pixels;
    return cv::Point(static_cast<int>(std::lround(px)), static_cast<int>(std::lround(py)));
  };
  // A state that occurred k times is a disc of k times the area (at most 9 times).
  const int radius = n <= 1000 ? 3 : 2;
  auto disc = [&](int i) {
    const double k = std::min(9.0, static_cast<double>(counts[static_cast<size_t>(i)]));
    return static_cast<int>(std::lround(radius * std::sqrt(k)));
  };
  for (int i = 0; i < n; ++i) {
    cv::circle(page, to_pixel(i), disc(i), colour(samples.values[static_cast<size_t>(i)]),
               cv::FILLED, cv::LINE_AA);
  }

  // The thumbnails: the left half of the chosen points (by x) in the left column, the rest in the
  // right one, each column ordered by y so that the lines do not cross.
  std::vector<int> by_x = result.thumbnails;
  std::stable_sort(by_x.begin(), by_x.end(),
                   [&](int a, int b) { return to_pixel(a).x < to_pixel(b).x; });
  const size_t left_count = by_x.size() / 2;
  for (int side = 0; side < 2; ++side) {
    std::vector<int> column(side == 0 ? by_x.begin() : by_x.begin() + left_count,
                            side == 0 ? by_x.begin() + left_count : by_x.end());
    std::stable_sort(column.begin(), column.end(),
                     [&](int a, int b) { return to_pixel(a).y < to_pixel(b).y; });
    const int x = side == 0 ? kMargin : right_x;
    for (size_t k = 0; k < column.size(); ++k) {
      const int i = column[k];
      const double slot = static_cast<double>(kPlotSide) / static_cast<double>(column.size());
      const int centre_y = plot_y + static_cast<int>((static_cast<double>(k) + 0.5) * slot);
      const int top = centre_y - (thumb_h + kLabelHeight) / 2;
      const cv::Point point = to_pixel(i);
      const cv::Point anchor(side == 0 ? x + thumb_w + 2 : x - 3, top + thumb_h / 2);
      cv::line(page, anchor, point, kLine, 1, cv::LINE_AA);
      cv::circle(page, point, disc(i) + 4, kInk, 2, cv::LINE_AA);
      const cv::Mat frame(samples.frame_height, samples.frame_width, CV_8UC1,
                          const_cast<uint8_t*>(samples.frames.data()) + frame_bytes * i);
      cv::Mat big, bgr;
      cv::resize(frame, big, cv::Size(thumb_w, thumb_h), 0, 0, cv::INTER_NEAREST);
      cv::cvtColor(big, bgr, cv::COLOR_GRAY2BGR);
      bgr.copyTo(page(cv::Rect(x, top, thumb_w, thumb_h)));
      const double v = samples.values[static_cast<size_t>(i)];
      cv::rectangle(page, cv::Rect(x - 2, top - 2, thumb_w + 4, thumb_h + 4), colour(v), 2);
      cv::putText(page, (samples.value_is_return ? "G " : "Q ") + Number(v),
                  cv::Point(x, top + thumb_h + kLabelHeight - 3), cv::FONT_HERSHEY_SIMPLEX, kFont,
                  kInk, 1, cv::LINE_AA);
    }
  }

  // The colour bar: high values at the top.
  for (int r = 0; r < kPlotSide; ++r) {
    const double v = hi - (hi - lo) * r / (kPlotSide - 1);
    cv::line(page, cv::Point(bar_x, plot_y + r), cv::Point(bar_x + kBarWidth - 1, plot_y + r),
             colour(v));
  }
  cv::rectangle(page, cv::Rect(bar_x, plot_y, kBarWidth, kPlotSide), kInk, 1);
  for (double t : NiceTicks(lo, hi, 6)) {
    if (t < lo || t > hi) continue;
    const int ty = plot_y + static_cast<int>(std::lround((hi - t) / (hi - lo) * (kPlotSide - 1)));
    cv::line(page, cv::Point(bar_x + kBarWidth, ty), cv::Point(bar_x + kBarWidth + 4, ty), kInk);
    cv::putText(page, Number(std::abs(t) < 1e-12 * (hi - lo) ? 0.0 : t),
                cv::Point(bar_x + kBarWidth + 7, ty + 5), cv::FONT_HERSHEY_SIMPLEX, kFont, kInk, 1,
                cv::LINE_AA);
  }
  cv::putText(page, samples.value_is_return ? "return G" : "max_a Q",
              cv::Point(bar_x - 8, plot_y - 8), cv::FONT_HERSHEY_SIMPLEX, kFont, kInk, 1,
              cv::LINE_AA);

  std::vector<uchar> png;
  if (!cv::imencode(".png", page, png)) throw std::runtime_error("cannot encode " + path);
  WriteFileAtomically(path, std::string(png.begin(), png.end()), "t-SNE map");
  result.width = width;
  result.height = height;
  return result;
}

}  // namespace rl::evaluator
