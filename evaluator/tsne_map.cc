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
#include "evaluator/plot.h"
#include "evaluator/raster_canvas.h"
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
                           const std::function<void(int states)>& after_step) {
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
      const envs::StepResult step = env->Step(action);
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
      if (after_step) after_step(n);
      if (done || (!s.value_is_return && n == states)) break;
    }
    ++s.episodes;
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
constexpr int kColumnGap = 36;    // between a column of thumbnails and the plot
constexpr int kThumbSide = 96;    // the longer side of a thumbnail
constexpr int kLabelHeight = 18;  // below a thumbnail
constexpr int kBarWidth = 16;     // the colour bar
constexpr int kBarLabels = 64;    // room for its tick labels
// Text: labels at OpenCV's Hershey scale 0.45, the title at 0.55 at most.
constexpr double kFontSize = 0.45 * RasterCanvas::kPixelsPerScale;
constexpr double kTitleSize = 0.55 * RasterCanvas::kPixelsPerScale;
constexpr plot::Colour kInk = plot::Colour::Hex(0x282828);
constexpr plot::Colour kLine = plot::Colour::Hex(0x6e6e6e);
constexpr plot::Colour kFrame = plot::Colour::Hex(0xd2d2d2);

// The viridis colour map (OpenCV's), 256 entries.
std::vector<plot::Colour> Viridis() {
  cv::Mat ramp(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
  cv::Mat colours;
  cv::applyColorMap(ramp, colours, cv::COLORMAP_VIRIDIS);
  std::vector<plot::Colour> palette;
  for (int i = 0; i < 256; ++i) {
    const cv::Vec3b c = colours.at<cv::Vec3b>(0, i);  // BGR
    palette.push_back({c[2], c[1], c[0]});
  }
  return palette;
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

plot::Font TextFont(double size = kFontSize) {
  plot::Font f;
  f.size = size;
  f.colour = kInk;
  return f;
}

// Where the parts of the picture go: thumbnails left and right of the square plot, then the
// colour bar.
struct Layout {
  int thumb_w = 0, thumb_h = 0;  // frames scaled up by a whole factor to at most kThumbSide
  int plot_x = 0, plot_y = kTitleHeight;
  int right_x = 0;  // the right column of thumbnails
  int bar_x = 0;
  int width = 0, height = 0;
};

Layout MakeLayout(int frame_height, int frame_width) {
  Layout l;
  const int scale = std::max(1, kThumbSide / std::max(frame_height, frame_width));
  l.thumb_w = frame_width * scale;
  l.thumb_h = frame_height * scale;
  l.plot_x = kMargin + l.thumb_w + kColumnGap;
  l.right_x = l.plot_x + kPlotSide + kColumnGap;
  l.bar_x = l.right_x + l.thumb_w + kColumnGap;
  l.width = l.bar_x + kBarWidth + kBarLabels;
  l.height = l.plot_y + kPlotSide + kMargin;
  return l;
}

// The title, shrunk to end before the colour bar's label.
void DrawTitle(RasterCanvas* canvas, const Layout& l, const std::string& title) {
  double size = kTitleSize;
  constexpr int kHalfGap = kColumnGap / 2;
  const double room = l.bar_x - kHalfGap - kMargin;
  while (size > 0.3 * RasterCanvas::kPixelsPerScale + 1e-9 &&
         canvas->TextWidth(title, size) > room) {
    size -= 0.05 * RasterCanvas::kPixelsPerScale;
  }
  canvas->Text({kMargin, 22}, title, TextFont(size));
}

// The points of the map and how they are drawn.
struct Scatter {
  std::vector<plot::Point> at;  // pixels
  std::vector<double> radius;
  const std::vector<double>* values = nullptr;
};

// The thumbnails: the left half of the chosen points (by x) in the left column, the rest in the
// right one, each column ordered by y so that the lines do not cross; each joined to its ringed
// point and labelled with its value.
void DrawThumbnails(RasterCanvas* canvas, const Layout& l, const StateSamples& samples,
                    const std::vector<int>& chosen, const Scatter& scatter,
                    const plot::ColourScale& colour) {
  std::vector<int> by_x = chosen;
  std::stable_sort(by_x.begin(), by_x.end(), [&](int a, int b) {
    return std::lround(scatter.at[static_cast<size_t>(a)].x) <
           std::lround(scatter.at[static_cast<size_t>(b)].x);
  });
  const size_t left_count = by_x.size() / 2;
  const size_t frame_bytes = static_cast<size_t>(samples.frame_height) * samples.frame_width;
  for (int side = 0; side < 2; ++side) {
    std::vector<int> column(side == 0 ? by_x.begin() : by_x.begin() + left_count,
                            side == 0 ? by_x.begin() + left_count : by_x.end());
    std::stable_sort(column.begin(), column.end(), [&](int a, int b) {
      return std::lround(scatter.at[static_cast<size_t>(a)].y) <
             std::lround(scatter.at[static_cast<size_t>(b)].y);
    });
    const int x = side == 0 ? kMargin : l.right_x;
    for (size_t k = 0; k < column.size(); ++k) {
      const auto i = static_cast<size_t>(column[k]);
      const double slot = static_cast<double>(kPlotSide) / static_cast<double>(column.size());
      const int centre_y = l.plot_y + static_cast<int>((static_cast<double>(k) + 0.5) * slot);
      const int top = centre_y - (l.thumb_h + kLabelHeight) / 2;
      const int middle = top + l.thumb_h / 2;
      const plot::Point anchor{static_cast<double>(side == 0 ? x + l.thumb_w + 2 : x - 3),
                               static_cast<double>(middle)};
      canvas->Line(anchor, scatter.at[i], plot::Paint::Stroke(kLine));
      canvas->Circle(scatter.at[i], std::lround(scatter.radius[i]) + 4,
                     plot::Paint::Stroke(kInk, 2));
      const cv::Mat frame(samples.frame_height, samples.frame_width, CV_8UC1,
                          const_cast<uint8_t*>(samples.frames.data()) + frame_bytes * i);
      cv::Mat big, bgr;
      cv::resize(frame, big, cv::Size(l.thumb_w, l.thumb_h), 0, 0, cv::INTER_NEAREST);
      cv::cvtColor(big, bgr, cv::COLOR_GRAY2BGR);
      bgr.copyTo(canvas->image()(cv::Rect(x, top, l.thumb_w, l.thumb_h)));
      const double v = (*scatter.values)[i];
      plot::Paint border = plot::Paint::Stroke(colour(v), 2);
      border.crisp = true;
      canvas->Rect({x - 2.0, top - 2.0}, l.thumb_w + 4, l.thumb_h + 4, border);
      canvas->Text(
          {static_cast<double>(x), static_cast<double>(top + l.thumb_h + kLabelHeight - 3)},
          (samples.value_is_return ? "G " : "Q ") + Number(v), TextFont());
    }
  }
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
  const auto [lo, hi] = std::minmax_element(samples.values.begin(), samples.values.end());
  result.value_min = *lo;
  result.value_max = *hi;
  const plot::ColourScale colour(*lo, *hi, Viridis());
  result.thumbnails = ThumbnailStates(samples, kTsneMapThumbnails);

  const Layout layout = MakeLayout(samples.frame_height, samples.frame_width);
  RasterCanvas canvas(layout.width, layout.height);
  DrawTitle(&canvas, layout,
            "t-SNE of the last hidden layer (" + std::to_string(result.features) +
                " features): " + std::to_string(result.states) + " states" +
                (n < result.states ? " (" + std::to_string(n) + " distinct)" : std::string()) +
                ", by " + (samples.value_is_return ? "return" : "value"));
  plot::Paint frame = plot::Paint::Stroke(kFrame);
  frame.crisp = true;
  canvas.Rect({static_cast<double>(layout.plot_x), static_cast<double>(layout.plot_y)}, kPlotSide,
              kPlotSide, frame);
  // The embedding in the square, one scale for both axes (t-SNE distances are isotropic); a
  // state that occurred k times is a disc of k times the area (at most 9 times).
  std::vector<plot::Point> embedded;
  for (int i = 0; i < n; ++i) embedded.push_back({y(0, i), y(1, i)});
  const plot::SquareMap to_pixel(
      embedded, {static_cast<double>(layout.plot_x), static_cast<double>(layout.plot_y)}, kPlotSide,
      12);
  Scatter scatter;
  scatter.values = &samples.values;
  const double radius = n <= 1000 ? 3 : 2;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<size_t>(i);
    scatter.at.push_back(to_pixel(embedded[k]));
    scatter.radius.push_back(radius * std::sqrt(std::min(9.0, static_cast<double>(counts[k]))));
    canvas.Circle(scatter.at[k], std::lround(scatter.radius[k]),
                  plot::Paint::Fill(colour(samples.values[k])));
  }
  DrawThumbnails(&canvas, layout, samples, result.thumbnails, scatter, colour);
  plot::DrawColourBar(
      &canvas, colour, {static_cast<double>(layout.bar_x), static_cast<double>(layout.plot_y)},
      kBarWidth, kPlotSide, samples.value_is_return ? "return G" : "max_a Q", TextFont());

  std::vector<uchar> png;
  if (!cv::imencode(".png", canvas.image(), png)) throw std::runtime_error("cannot encode " + path);
  WriteFileAtomically(path, std::string(png.begin(), png.end()), "t-SNE map");
  result.width = layout.width;
  result.height = layout.height;
  return result;
}

}  // namespace rl::evaluator
