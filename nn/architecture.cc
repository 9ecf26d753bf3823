// Parsing of architecture strings (BuildFromArchitecture, declared in nn/sequential.h).
#include <algorithm>
#include <charconv>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nn/activations.h"
#include "nn/batch_norm.h"
#include "nn/conv2d.h"
#include "nn/dueling.h"
#include "nn/flatten.h"
#include "nn/layer_norm.h"
#include "nn/linear.h"
#include "nn/pool2d.h"
#include "nn/sequential.h"

namespace rl::nn {
namespace {

// Throws the error of BuildFromArchitecture for `arch`.
[[noreturn]] void ArchError(const std::string& arch, const std::string& what) {
  throw std::invalid_argument("architecture '" + arch + "': " + what);
}

// One parsed layer: "name" or "name(arg,...)".
struct LayerSpec {
  std::string name;
  std::vector<std::string> args;
  bool has_parens = false;
};

std::string Trim(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const size_t last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

// Splits `arch` at the commas that are not inside parentheses.
std::vector<LayerSpec> ParseArchitecture(const std::string& arch) {
  std::vector<std::string> parts;
  std::string current;
  int depth = 0;
  for (char ch : arch) {
    if (ch == '(') ++depth;
    if (ch == ')' && --depth < 0) ArchError(arch, "unbalanced ')'");
    if (ch == ',' && depth == 0) {
      parts.push_back(current);
      current.clear();
    } else {
      current += ch;
    }
  }
  if (depth != 0) ArchError(arch, "unbalanced '('");
  parts.push_back(current);

  std::vector<LayerSpec> specs;
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string part = Trim(parts[i]);
    if (part.empty()) ArchError(arch, "layer " + std::to_string(i) + " is empty");
    LayerSpec spec;
    const size_t open = part.find('(');
    spec.name = Trim(part.substr(0, open));
    if (open != std::string::npos) {
      spec.has_parens = true;
      if (part.back() != ')') {
        ArchError(arch, "layer " + std::to_string(i) + " '" + part + "' has text after ')'");
      }
      std::string inner = part.substr(open + 1, part.size() - open - 2);
      if (!Trim(inner).empty()) {
        size_t start = 0;
        while (true) {
          const size_t comma = inner.find(',', start);
          spec.args.push_back(Trim(inner.substr(start, comma - start)));
          if (comma == std::string::npos) break;
          start = comma + 1;
        }
      }
    }
    specs.push_back(std::move(spec));
  }
  return specs;
}

int ParseInt(const std::string& arch, const std::string& layer, const std::string& s,
             bool may_be_zero) {
  int value = 0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, value);
  if (s.empty() || ec != std::errc() || ptr != end || value < 0 || (value == 0 && !may_be_zero)) {
    ArchError(arch, "layer '" + layer + "': '" + s + "' is not a " +
                        (may_be_zero ? "non-negative" : "positive") + " integer");
  }
  return value;
}

float ParseFloat(const std::string& arch, const std::string& layer, const std::string& s) {
  try {
    size_t used = 0;
    const float v = std::stof(s, &used);
    if (used == s.size()) return v;
  } catch (const std::exception&) {
  }
  ArchError(arch, "layer '" + layer + "': '" + s + "' is not a number");
}

// The known layers: name, argument names (empty: takes no arguments) and a factory.
struct LayerKind {
  const char* name;
  std::vector<const char*> args;
  std::unique_ptr<Layer> (*make)(const std::vector<int>& a, std::mt19937* rng);
};

const std::vector<LayerKind>& LayerKinds() {
  static const std::vector<LayerKind> kinds = {
      {"linear",
       {"in", "out"},
       [](const std::vector<int>& a, std::mt19937* rng) -> std::unique_ptr<Layer> {
         return std::make_unique<Linear>(a[0], a[1], rng);
       }},
      {"conv2d",
       {"in_channels", "out_channels", "kernel", "stride", "padding", "height", "width"},
       [](const std::vector<int>& a, std::mt19937* rng) -> std::unique_ptr<Layer> {
         return std::make_unique<Conv2d>(a[0], a[1], a[2], a[3], a[4], a[5], a[6], rng);
       }},
      {"batchnorm2d",
       {"channels", "height", "width"},
       [](const std::vector<int>& a, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<BatchNorm2d>(a[0], a[1], a[2]);
       }},
      {"layernorm",
       {"features"},
       [](const std::vector<int>& a, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<LayerNorm>(a[0]);
       }},
      {"dueling",
       {"in", "hidden", "actions"},
       [](const std::vector<int>& a, std::mt19937* rng) -> std::unique_ptr<Layer> {
         return std::make_unique<Dueling>(a[0], a[1], a[2], rng);
       }},
      {"maxpool2d",
       {"channels", "kernel", "height", "width"},
       [](const std::vector<int>& a, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<Pool2d>(Pool2d::Mode::kMax, a[0], a[1], a[2], a[3]);
       }},
      {"avgpool2d",
       {"channels", "kernel", "height", "width"},
       [](const std::vector<int>& a, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<Pool2d>(Pool2d::Mode::kAverage, a[0], a[1], a[2], a[3]);
       }},
      {"relu",
       {},
       [](const std::vector<int>& /*a*/, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<ReLU>();
       }},
      {"tanh",
       {},
       [](const std::vector<int>& /*a*/, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<Tanh>();
       }},
      {"flatten",
       {},
       [](const std::vector<int>& /*a*/, std::mt19937* /*rng*/) -> std::unique_ptr<Layer> {
         return std::make_unique<Flatten>();
       }},
  };
  return kinds;
}

// "conv2d(in_channels,out_channels,...)" or "relu".
std::string Signature(const LayerKind& kind) {
  if (kind.args.empty()) return kind.name;
  std::string s = kind.name;
  for (size_t i = 0; i < kind.args.size(); ++i) {
    s += i == 0 ? '(' : ',';
    s += kind.args[i];
  }
  s += ')';
  return s;
}

// Refuses a layer beyond the limits of sequential.h, before it is built; adds its parameters
// to *params. Products in double: the arguments are checked one by one first, so they are exact
// enough to compare with the limits.
void CheckLimits(const std::string& arch, const std::string& where, const std::string& name,
                 const std::vector<int>& a, double* params) {
  for (const int v : a) {
    if (v > kMaxArchitectureInteger) {
      ArchError(arch, where + ": " + std::to_string(v) + " is above the limit of " +
                          std::to_string(kMaxArchitectureInteger));
    }
  }
  const auto image = [&](double channels, double height, double width) {
    if (channels * height * width > static_cast<double>(kMaxArchitectureImage)) {
      ArchError(arch, where + ": an image of more than " + std::to_string(kMaxArchitectureImage) +
                          " values");
    }
  };
  const auto d = [&](size_t i) { return static_cast<double>(a[i]); };
  if (name == "linear") {
    *params += d(0) * d(1) + d(1);
  } else if (name == "conv2d") {
    image(d(0), d(5) + 2 * d(4), d(6) + 2 * d(4));
    image(d(1), d(5) + 2 * d(4), d(6) + 2 * d(4));  // bounds the output
    *params += d(1) * d(0) * d(2) * d(2) + d(1);
  } else if (name == "batchnorm2d") {
    image(d(0), d(1), d(2));
    *params += 2 * d(0);
  } else if (name == "layernorm") {
    *params += 2 * d(0);
  } else if (name == "dueling") {
    *params += 2 * (d(0) + 1) * d(1) + (d(1) + 1) * (d(2) + 1);
  } else if (name == "maxpool2d" || name == "avgpool2d") {
    image(d(0), d(2), d(3));
  }
  if (*params > static_cast<double>(kMaxArchitectureParameters)) {
    ArchError(arch, where + ": the network would hold more than " +
                        std::to_string(kMaxArchitectureParameters) + " parameters");
  }
}

}  // namespace

Sequential BuildFromArchitecture(const std::string& arch, std::mt19937* rng) {
  if (Trim(arch).empty()) ArchError(arch, "no layers");
  Sequential net;
  const std::vector<LayerSpec> specs = ParseArchitecture(arch);
  double params = 0;
  for (size_t i = 0; i < specs.size(); ++i) {
    const LayerSpec& spec = specs[i];
    const std::string where = "layer " + std::to_string(i) + " '" + spec.name + "'";
    if (spec.name == "bounded") {
      // bounded(n,low_1,high_1,...): an integer, then 2n floats.
      if (spec.args.empty()) ArchError(arch, where + " needs bounded(n,low_1,high_1,...)");
      const int n = ParseInt(arch, spec.name, spec.args[0], false);
      if (spec.args.size() != 1 + 2 * static_cast<size_t>(n)) {
        ArchError(arch, where + " needs " + std::to_string(2 * int64_t{n}) + " bounds after n");
      }
      CheckLimits(arch, where, spec.name, {n}, &params);
      std::vector<float> low, high;
      for (int k = 0; k < n; ++k) {
        low.push_back(ParseFloat(arch, spec.name, spec.args[1 + 2 * static_cast<size_t>(k)]));
        high.push_back(ParseFloat(arch, spec.name, spec.args[2 + 2 * static_cast<size_t>(k)]));
      }
      try {
        net.Add(std::make_unique<Bounded>(std::move(low), std::move(high)));
      } catch (const std::invalid_argument& e) {
        ArchError(arch, where + ": " + e.what());
      }
      continue;
    }
    const auto& kinds = LayerKinds();
    const auto kind = std::find_if(kinds.begin(), kinds.end(),
                                   [&](const LayerKind& k) { return spec.name == k.name; });
    if (kind == kinds.end()) {
      std::string known;
      for (const LayerKind& k : kinds) {
        if (!known.empty()) known += ", ";
        known += Signature(k);
      }
      ArchError(arch, "unknown " + where + " (known: " + known + ")");
    }
    if (kind->args.empty() && spec.has_parens) ArchError(arch, where + " takes no arguments");
    if (spec.args.size() != kind->args.size()) {
      ArchError(arch, where + " needs " + Signature(*kind) + ", got " +
                          std::to_string(spec.args.size()) + " arguments");
    }
    std::vector<int> values;
    for (size_t a = 0; a < spec.args.size(); ++a) {
      const bool may_be_zero = spec.name == "conv2d" && a == 4;  // The padding.
      values.push_back(ParseInt(arch, spec.name, spec.args[a], may_be_zero));
    }
    CheckLimits(arch, where, spec.name, values, &params);
    try {
      net.Add(kind->make(values, rng));
    } catch (const std::invalid_argument& e) {
      ArchError(arch, where + ": " + e.what());
    }
  }
  return net;
}

}  // namespace rl::nn
