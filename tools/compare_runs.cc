#include "tools/compare_runs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "common/atomic_file.h"
#include "common/text_format.h"
#include "evaluator/learning_curve.h"

namespace rl::tools {
namespace {

namespace fs = std::filesystem;
using evaluator::EvalRecord;
using evaluator::HtmlEscape;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- config.ini ----

// The text after `key` up to the first of `stops` (or the end of the line), e.g. the goal of
// "# actors = 4 (of 4), seed = 1, goal = 475, time budget = 600 s".
std::optional<std::string> FieldAfter(const std::string& line, const std::string& key,
                                      const char* stops) {
  const size_t at = line.find(key);
  if (at == std::string::npos) return std::nullopt;
  const size_t begin = at + key.size();
  return line.substr(begin, line.find_first_of(stops, begin) - begin);
}

std::optional<double> ParseNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return v;
}

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// ---- Numbers on the page ----

std::string Format(const char* fmt, double v) { return FormatDouble(fmt, v); }

// The page's counts, durations and scores are the report's (common/text_format.h); a missing
// duration is a dash.
std::string Thousands(double value) { return rl::Thousands(std::llround(value)); }
std::string Duration(double seconds) { return rl::Duration(seconds, "\xE2\x80\x94"); }

// A tick value: whole numbers in full, others with at most three significant digits.
std::string Plain(double v) {
  if (std::abs(v) < 1e-9) v = 0;
  return Format(std::abs(v) < 1e15 && v == std::round(v) ? "%.0f" : "%.3g", v);
}

// An env-steps tick: 0, 800, 50k, 1.5M.
std::string CountTick(double v) {
  const double a = std::abs(v);
  if (a >= 1e9) return Plain(v / 1e9) + "G";
  if (a >= 1e6) return Plain(v / 1e6) + "M";
  if (a >= 1e3) return Plain(v / 1e3) + "k";
  return Plain(v);
}

// A pixel coordinate.
std::string Px(double v) { return Format("%.1f", v); }

constexpr char kDash[] = "\xE2\x80\x94";

// ---- Colours ----

// One colour per group, in order (none of them the goal's red).
constexpr const char* kPalette[] = {"#1f6feb", "#bf3989", "#1a7f37", "#bc4c00",
                                    "#8250df", "#0a7f86", "#9a6700", "#57606a"};
constexpr char kGoalColor[] = "#d1242f";
constexpr char kGridColor[] = "#e6e8eb";
constexpr char kAxisColor[] = "#57606a";
constexpr char kTextColor[] = "#24292f";

// Plots with more runs than this name none of them at their ends (the lines' tooltips still do).
constexpr size_t kMaxRunLabels = 12;

// ---- Groups ----

struct Group {
  std::string preset;
  std::string env_id;
  double goal = kNaN;
  std::string color;
  std::vector<const CompareRun*> runs;
};

std::vector<Group> MakeGroups(const std::vector<CompareRun>& runs) {
  std::vector<Group> groups;
  for (const CompareRun& run : runs) {
    auto it = std::find_if(groups.begin(), groups.end(),
                           [&](const Group& g) { return g.preset == run.preset; });
    if (it == groups.end()) {
      Group g;
      g.preset = run.preset;
      g.env_id = run.env_id;
      g.color = kPalette[groups.size() % std::size(kPalette)];
      groups.push_back(std::move(g));
      it = groups.end() - 1;
    }
    if (!std::isfinite(it->goal)) it->goal = run.goal;
    it->runs.push_back(&run);
  }
  return groups;
}

double XOf(const EvalRecord& r, CurveAxis axis) {
  return axis == CurveAxis::kEnvSteps ? static_cast<double>(r.env_steps) : r.wall_seconds;
}

// ---- The plot ----

struct Plot {
  std::string title;
  std::string x_label;
  CurveAxis axis = CurveAxis::kEnvSteps;
  int width = 1080;
  int height = 420;
};

struct Scale {
  double lo, hi, p0, p1;
  double operator()(double v) const { return p0 + (v - lo) / (hi - lo) * (p1 - p0); }
};

// "M x0,y0 H x1 V y1 H x2 V y2 ...": a step function drawn as it holds.
std::string StepPath(const std::vector<std::pair<double, double>>& pts, const Scale& sx,
                     const Scale& sy) {
  std::string d;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (i == 0) {
      d += "M" + Px(sx(pts[i].first)) + "," + Px(sy(pts[i].second));
    } else {
      d += " H" + Px(sx(pts[i].first)) + " V" + Px(sy(pts[i].second));
    }
  }
  return d;
}

std::string RenderPlot(const std::vector<Group>& groups, const Plot& plot) {
  constexpr double kLeft = 72, kRight = 24, kTop = 40, kBottom = 56;
  // The curves of every group, in the axis' units.
  struct Curves {
    std::vector<std::vector<StepPoint>> runs;
    std::vector<GroupPoint> combined;
  };
  std::vector<Curves> curves;
  for (const Group& g : groups) {
    Curves c;
    for (const CompareRun* run : g.runs) c.runs.push_back(BestSoFar(*run, plot.axis));
    c.combined = CombineSteps(c.runs);
    curves.push_back(std::move(c));
  }
  std::set<double> goals;
  for (const Group& g : groups) {
    if (std::isfinite(g.goal)) goals.insert(g.goal);
  }

  // Ranges: x from 0, y covering every value, 0 and the goals.
  double x_hi = 0, y_lo = 0, y_hi = 0;
  bool any = false;
  for (const Curves& c : curves) {
    for (const std::vector<StepPoint>& run : c.runs) {
      for (const StepPoint& p : run) {
        x_hi = std::max(x_hi, p.x);
        y_lo = std::min(y_lo, p.y);
        y_hi = std::max(y_hi, p.y);
        any = true;
      }
    }
  }
  for (double g : goals) {
    y_lo = std::min(y_lo, g);
    y_hi = std::max(y_hi, g);
  }
  double unit = 1;
  std::string x_label = plot.x_label;
  if (plot.axis == CurveAxis::kWallSeconds) {
    std::string unit_name = "s";
    if (x_hi >= 2 * 3600.0) {
      unit = 3600;
      unit_name = "h";
    } else if (x_hi >= 120.0) {
      unit = 60;
      unit_name = "min";
    }
    x_label += " (" + unit_name + ")";
  }
  if (!any || x_hi <= 0) x_hi = unit;
  const std::vector<double> x_ticks = evaluator::NiceTicks(0, x_hi / unit, 8);
  const std::vector<double> y_ticks = evaluator::NiceTicks(y_lo, y_hi, 6);
  const double w = plot.width, h = plot.height;
  const Scale sx{x_ticks.front() * unit, x_ticks.back() * unit, kLeft, w - kRight};
  const Scale sy{y_ticks.front(), y_ticks.back(), h - kBottom, kTop};

  std::string s;
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(plot.width) +
       "\" height=\"" + std::to_string(plot.height) + "\" viewBox=\"0 0 " +
       std::to_string(plot.width) + " " + std::to_string(plot.height) +
       "\" font-family=\"-apple-system, 'Segoe UI', Helvetica, Arial, sans-serif\" "
       "font-size=\"12\" fill=\"" +
       kTextColor + "\" role=\"img\">\n";
  s += "<title>" + HtmlEscape(plot.title) + "</title>\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  s += "<text x=\"" + Px(kLeft) + "\" y=\"22\" font-size=\"14\" font-weight=\"600\">" +
       HtmlEscape(plot.title) + "</text>\n";

  // Grid, ticks, axes.
  s += "<g stroke=\"" + std::string(kGridColor) + "\" stroke-width=\"1\">";
  for (double t : x_ticks) {
    s += "<line x1=\"" + Px(sx(t * unit)) + "\" y1=\"" + Px(sy.p1) + "\" x2=\"" + Px(sx(t * unit)) +
         "\" y2=\"" + Px(sy.p0) + "\"/>";
  }
  for (double t : y_ticks) {
    s += "<line x1=\"" + Px(sx.p0) + "\" y1=\"" + Px(sy(t)) + "\" x2=\"" + Px(sx.p1) + "\" y2=\"" +
         Px(sy(t)) + "\"/>";
  }
  s += "</g>\n<g font-size=\"11\" fill=\"" + std::string(kAxisColor) + "\">";
  for (double t : x_ticks) {
    const std::string label = plot.axis == CurveAxis::kEnvSteps ? CountTick(t) : Plain(t);
    s += "<text x=\"" + Px(sx(t * unit)) + "\" y=\"" + Px(sy.p0 + 16) +
         "\" text-anchor=\"middle\">" + HtmlEscape(label) + "</text>";
  }
  for (double t : y_ticks) {
    s += "<text x=\"" + Px(sx.p0 - 8) + "\" y=\"" + Px(sy(t) + 4) + "\" text-anchor=\"end\">" +
         HtmlEscape(Plain(t)) + "</text>";
  }
  s += "</g>\n";
  s += "<path d=\"M" + Px(sx.p0) + "," + Px(sy.p1) + " V" + Px(sy.p0) + " H" + Px(sx.p1) +
       "\" fill=\"none\" stroke=\"" + kAxisColor + "\" stroke-width=\"1\"/>\n";
  s += "<text x=\"" + Px((sx.p0 + sx.p1) / 2) + "\" y=\"" + Px(h - 14) +
       "\" text-anchor=\"middle\">" + HtmlEscape(x_label) + "</text>\n";
  s += "<text transform=\"translate(18," + Px((sy.p0 + sy.p1) / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">best evaluation mean so far</text>\n";

  // Names at the runs' last evaluations (placed after the lines; see below).
  struct Label {
    double x, y;  // the dot
    std::string text, color;
  };
  std::vector<Label> labels;

  // Per group: the band, each run thin, the mean thick (bands first, so no band hides a line).
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    const std::vector<GroupPoint>& c = curves[gi].combined;
    if (c.empty() || groups[gi].runs.size() < 2) continue;
    std::vector<std::pair<double, double>> hi, lo;
    for (const GroupPoint& p : c) {
      hi.emplace_back(p.x, p.max);
      lo.emplace_back(p.x, p.min);
    }
    std::string d = StepPath(hi, sx, sy);
    // Back along the lower edge: at each x, down to the value before it, then left.
    d += " V" + Px(sy(lo.back().second));
    for (size_t i = lo.size() - 1; i > 0; --i) {
      d += " H" + Px(sx(lo[i].first)) + " V" + Px(sy(lo[i - 1].second));
    }
    d += " H" + Px(sx(lo.front().first)) + " Z";
    s += "<path class=\"band\" d=\"" + d + "\" fill=\"" + groups[gi].color +
         "\" fill-opacity=\"0.14\" stroke=\"none\"><title>" + HtmlEscape(groups[gi].preset) +
         ": min to max of " + std::to_string(groups[gi].runs.size()) + " runs</title></path>\n";
  }
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    const Group& g = groups[gi];
    const bool alone = g.runs.size() == 1;
    for (size_t ri = 0; ri < g.runs.size(); ++ri) {
      const std::vector<StepPoint>& run = curves[gi].runs[ri];
      if (run.empty()) continue;
      std::vector<std::pair<double, double>> pts;
      for (const StepPoint& p : run) pts.emplace_back(p.x, p.y);
      s += "<path class=\"run\" d=\"" + StepPath(pts, sx, sy) + "\" fill=\"none\" stroke=\"" +
           g.color + "\" stroke-width=\"" + (alone ? "2.2" : "1") + "\" stroke-opacity=\"" +
           (alone ? "1" : "0.55") + "\" stroke-linejoin=\"round\"><title>" +
           HtmlEscape(g.runs[ri]->label) + "</title></path>";
      // Where the run's evaluations end.
      s += "<circle cx=\"" + Px(sx(run.back().x)) + "\" cy=\"" + Px(sy(run.back().y)) + "\" r=\"" +
           (alone ? "3.5" : "2.5") + "\" fill=\"" + g.color + "\"><title>" +
           HtmlEscape(g.runs[ri]->label) + ": last evaluation</title></circle>\n";
      labels.push_back({sx(run.back().x), sy(run.back().y), g.runs[ri]->label, g.color});
    }
    if (!alone && !curves[gi].combined.empty()) {
      std::vector<std::pair<double, double>> pts;
      for (const GroupPoint& p : curves[gi].combined) pts.emplace_back(p.x, p.mean);
      s += "<path class=\"mean\" d=\"" + StepPath(pts, sx, sy) + "\" fill=\"none\" stroke=\"" +
           g.color + "\" stroke-width=\"2.6\" stroke-linejoin=\"round\"><title>" +
           HtmlEscape(g.preset) + ": mean of " + std::to_string(g.runs.size()) +
           " runs</title></path>\n";
    }
  }

  // Each run's name left of its last dot, above it or else below it (clear of the line, which
  // comes in level from the left), the nearest spot that overlaps no other name and stays in the
  // plot (11 px text: about 6.2 px a character); left out when there are too many to read.
  if (labels.size() <= kMaxRunLabels) {
    std::stable_sort(labels.begin(), labels.end(),
                     [](const Label& a, const Label& b) { return a.y < b.y; });
    std::vector<std::array<double, 3>> placed;  // left, right, baseline
    std::string text;
    for (const Label& l : labels) {
      const double right = l.x - 5, left = right - 6.2 * static_cast<double>(l.text.size());
      const auto free = [&](double y) {
        if (y < sy.p1 - 6 || y > sy.p0 - 3) return false;  // may reach into the top margin
        for (const auto& [pl, pr, py] : placed) {
          if (left < pr && pl < right && std::abs(py - y) < 12) return false;
        }
        return true;
      };
      double y = l.y - 6;
      for (int k = 0; k < 40; ++k) {
        // Above at -6, -19, -32, ...; below at +15, +28, ...
        const double candidate = k % 2 == 0 ? l.y - 6 - 13.0 * (k / 2) : l.y + 15 + 13.0 * (k / 2);
        if (free(candidate)) {
          y = candidate;
          break;
        }
      }
      placed.push_back({left, right, y});
      text += "<text x=\"" + Px(right) + "\" y=\"" + Px(y) + "\" text-anchor=\"end\" fill=\"" +
              l.color + "\">" + HtmlEscape(l.text) + "</text>";
    }
    s += "<g class=\"names\" font-size=\"11\" stroke=\"#ffffff\" stroke-width=\"3\" "
         "paint-order=\"stroke\" stroke-linejoin=\"round\">" +
         text + "</g>\n";
  }

  // The goals, dashed and labelled at the left.
  for (double goal : goals) {
    const double gy = sy(goal);
    s += "<line class=\"goal\" x1=\"" + Px(sx.p0) + "\" y1=\"" + Px(gy) + "\" x2=\"" + Px(sx.p1) +
         "\" y2=\"" + Px(gy) + "\" stroke=\"" + kGoalColor +
         "\" stroke-width=\"1.2\" stroke-dasharray=\"6 4\"/>\n";
    s += "<text x=\"" + Px(sx.p0 + 6) + "\" y=\"" + Px(gy - 5) + "\" font-size=\"11\" fill=\"" +
         kGoalColor + "\">goal " + HtmlEscape(Format("%g", goal)) + "</text>\n";
  }
  s += "</svg>\n";
  return s;
}

// ---- The page ----

constexpr char kCss[] = R"css(
:root { --fg: #24292f; --muted: #57606a; --line: #d0d7de; --soft: #f6f8fa; --good: #1a7f37; }
* { box-sizing: border-box; }
body { margin: 0; background: #eef1f4; color: var(--fg);
       font: 15px/1.5 -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; }
main { max-width: 1180px; margin: 0 auto; padding: 28px 20px 48px; }
h1 { margin: 0 0 2px; font-size: 26px; }
h2 { font-size: 18px; margin: 0 0 8px; }
h2 .env { color: var(--muted); font-weight: 400; }
.meta { color: var(--muted); margin: 0 0 20px; font-size: 13px; }
section { background: #fff; border: 1px solid var(--line); border-radius: 8px;
          padding: 18px 20px; margin: 0 0 18px; }
.how { color: var(--muted); font-size: 13px; margin: 0 0 10px; }
.legend { display: flex; flex-wrap: wrap; gap: 6px 18px; margin: 0 0 10px; font-size: 14px; }
.legend span { white-space: nowrap; }
.swatch { display: inline-block; width: 12px; height: 12px; border-radius: 3px;
          vertical-align: -1px; margin-right: 6px; }
figure { margin: 0 0 10px; }
figure svg { display: block; max-width: 100%; height: auto; border: 1px solid var(--line);
             border-radius: 6px; }
.scroll { overflow-x: auto; }
table { width: 100%; border-collapse: collapse; font-size: 13px; }
th, td { padding: 5px 8px; border-bottom: 1px solid var(--line); text-align: right;
         white-space: nowrap; }
th { background: var(--soft); font-weight: 600; }
th:first-child, td:first-child { text-align: left; }
td small { display: block; color: var(--muted); font-size: 11.5px; font-weight: 400; }
td small.inline { display: inline; }
td.yes { color: var(--good); font-weight: 600; }
tr.group td:first-child { font-weight: 600; }
tr.sub th { background: #fff; text-align: left; padding-top: 12px; font-size: 13.5px; }
td, th { vertical-align: top; }
.legend .keys { margin-left: auto; color: var(--muted); font-size: 12.5px; }
.k { display: inline-block; width: 22px; margin: 0 5px 0 12px; vertical-align: 3px; }
.k.run { border-top: 1px solid var(--muted); }
.k.mean { border-top: 3px solid var(--muted); vertical-align: 2px; }
.k.band { height: 10px; background: rgba(87, 96, 106, .2); vertical-align: -1px; }
.k.goal { border-top: 1.5px dashed #d1242f; }
a { color: inherit; }
)css";

std::string Swatch(const std::string& color) {
  return "<span class=\"swatch\" style=\"background:" + color + "\"></span>";
}

double Mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return values.empty() ? kNaN : sum / static_cast<double>(values.size());
}

// The mean of `values`, and below it (when there are several) "min to max".
std::string MeanRange(const std::vector<double>& values, std::string (*fmt)(double)) {
  if (values.empty()) return kDash;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  std::string out = fmt(Mean(values));
  if (values.size() > 1) out += "<small>" + fmt(*lo) + " to " + fmt(*hi) + "</small>";
  return out;
}

// "37,035 steps" and below it "1 min 03 s".
std::string StepsAndTime(const EvalRecord& r) {
  return Thousands(static_cast<double>(r.env_steps)) + " steps<small>" + Duration(r.wall_seconds) +
         "</small>";
}

// The line styles of the plots, for the legend (drawn by the CSS of .k).
constexpr char kLegendKeys[] =
    "<i class=\"k run\"></i>a run <i class=\"k mean\"></i>mean of a preset's runs "
    "<i class=\"k band\"></i>their lowest to highest <i class=\"k goal\"></i>goal";

std::string ScoreStd(const EvalRecord& r) {
  return Score(r.mean) + " <small class=\"inline\">\xC2\xB1 " + Score(r.std) + "</small>";
}

std::string RunName(const CompareRun& run, const std::string& page_dir) {
  std::string name = HtmlEscape(run.label);
  if (page_dir.empty()) return name;
  std::error_code ec;
  const fs::path report = fs::path(run.dir) / "report" / evaluator::kReportIndex;
  if (!fs::is_regular_file(report, ec)) return name;
  const fs::path rel = fs::relative(fs::absolute(report, ec), fs::absolute(page_dir, ec), ec);
  if (ec || rel.empty()) return name;
  return "<a href=\"" + HtmlEscape(rel.generic_string()) + "\" title=\"the run's report\">" + name +
         "</a>";
}

}  // namespace

CompareRun LoadCompareRun(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(dir + ": not a folder");
  const fs::path config = fs::path(dir) / "config.ini";
  const fs::path eval = fs::path(dir) / "eval.jsonl";
  if (!fs::is_regular_file(config, ec)) {
    throw std::runtime_error(dir + ": no config.ini (not a run folder of scripts/launch.sh)");
  }
  if (!fs::is_regular_file(eval, ec)) {
    throw std::runtime_error(dir + ": no eval.jsonl (not a run folder, or no checkpoint scored)");
  }
  CompareRun run;
  run.dir = dir;
  run.label = fs::path(dir).lexically_normal().filename().string();
  if (run.label.empty()) {
    run.label = fs::path(dir).lexically_normal().parent_path().filename().string();
  }
  run.goal = kNaN;
  std::ifstream in(config);
  if (!in) throw std::runtime_error(dir + ": cannot read config.ini");
  bool in_section = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# Run of preset '", 0) == 0) {
      if (const auto p = FieldAfter(line, "# Run of preset '", "'")) run.preset = *p;
    } else if (line.rfind("# actors = ", 0) == 0) {
      if (const auto g = FieldAfter(line, "goal = ", ",")) {
        run.goal = ParseNumber(Trim(*g)).value_or(kNaN);
      }
      if (const auto s = FieldAfter(line, "seed = ", ",")) {
        const std::optional<double> v = ParseNumber(Trim(*s));
        if (v && *v == std::floor(*v)) run.seed = static_cast<int64_t>(*v);
      }
    } else if (!line.empty() && line[0] == '[') {
      in_section = true;
    } else if (!in_section && run.env_id.empty() && line.rfind('#', 0) != 0) {
      const size_t eq = line.find('=');
      if (eq != std::string::npos && Trim(line.substr(0, eq)) == "env") {
        run.env_id = Trim(line.substr(eq + 1));
      }
    }
  }
  if (run.preset.empty()) {
    throw std::runtime_error(dir +
                             ": config.ini has no \"# Run of preset\" line (not written by "
                             "scripts/launch.sh)");
  }
  run.records = evaluator::LoadJsonLines(eval.string(), &run.skipped_lines);
  if (run.records.empty()) {
    throw std::runtime_error(dir + ": eval.jsonl has no evaluation yet");
  }
  return run;
}

void MakeLabelsUnique(std::vector<CompareRun>* runs) {
  // The path components of every run, and how many of the last ones its label shows.
  std::vector<std::vector<std::string>> parts;
  std::vector<size_t> shown(runs->size(), 1);
  for (const CompareRun& run : *runs) {
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(run.dir, ec), ec);
    if (ec) p = fs::path(run.dir).lexically_normal();
    std::vector<std::string> c;
    for (const fs::path& part : p) {
      if (!part.empty() && part != "/") c.push_back(part.string());
    }
    if (c.empty()) c.push_back(run.dir);
    parts.push_back(std::move(c));
  }
  const auto label = [&](size_t i) {
    const std::vector<std::string>& c = parts[i];
    const size_t n = std::min(shown[i], c.size());
    std::string s;
    for (size_t k = c.size() - n; k < c.size(); ++k) s += (s.empty() ? "" : "/") + c[k];
    return s;
  };
  for (bool changed = true; changed;) {
    changed = false;
    std::map<std::string, std::vector<size_t>> by_label;
    for (size_t i = 0; i < runs->size(); ++i) by_label[label(i)].push_back(i);
    for (const auto& [name, same] : by_label) {
      if (same.size() < 2) continue;
      for (size_t i : same) {
        if (shown[i] < parts[i].size()) {
          ++shown[i];
          changed = true;
        }
      }
    }
  }
  for (size_t i = 0; i < runs->size(); ++i) (*runs)[i].label = label(i);
}

RunSummary Summarize(const CompareRun& run) {
  RunSummary s;
  s.evaluations = static_cast<int>(run.records.size());
  if (run.records.empty()) return s;
  const EvalRecord* best = nullptr;
  const EvalRecord* last = nullptr;
  const EvalRecord* goal = nullptr;
  for (const EvalRecord& r : run.records) {
    if (best == nullptr || r.mean > best->mean) best = &r;
    if (last == nullptr || r.update >= last->update) last = &r;
    if (std::isfinite(run.goal) && r.mean >= run.goal &&
        (goal == nullptr || r.update < goal->update)) {
      goal = &r;
    }
  }
  s.best = *best;
  s.final = *last;
  if (goal != nullptr) {
    s.goal_reached = true;
    s.first_goal = *goal;
  }
  return s;
}

std::vector<StepPoint> BestSoFar(const CompareRun& run, CurveAxis axis) {
  std::vector<StepPoint> pts;
  for (const EvalRecord& r : run.records) {
    const double x = XOf(r, axis);
    if (std::isfinite(x) && std::isfinite(r.mean)) pts.push_back({x, r.mean});
  }
  std::stable_sort(pts.begin(), pts.end(),
                   [](const StepPoint& a, const StepPoint& b) { return a.x < b.x; });
  std::vector<StepPoint> steps;
  for (const StepPoint& p : pts) {
    if (steps.empty() || p.y > steps.back().y) {
      steps.push_back(p);
    }
  }
  // The last evaluation ends the step function, at the best so far.
  if (!pts.empty() && pts.back().x > steps.back().x)
    steps.push_back({pts.back().x, steps.back().y});
  return steps;
}

std::vector<GroupPoint> CombineSteps(const std::vector<std::vector<StepPoint>>& runs) {
  if (runs.empty()) return {};
  double start = -std::numeric_limits<double>::infinity();
  std::set<double> xs;
  for (const std::vector<StepPoint>& run : runs) {
    if (run.empty()) return {};
    start = std::max(start, run.front().x);
    for (const StepPoint& p : run) xs.insert(p.x);
  }
  std::vector<GroupPoint> out;
  for (auto it = xs.lower_bound(start); it != xs.end(); ++it) {
    const double x = *it;
    GroupPoint g{x, 0, std::numeric_limits<double>::infinity(),
                 -std::numeric_limits<double>::infinity()};
    for (const std::vector<StepPoint>& run : runs) {
      // The last point at or before x (there is one: x >= every run's first x).
      const auto after = std::upper_bound(run.begin(), run.end(), x,
                                          [](double v, const StepPoint& p) { return v < p.x; });
      const double y = std::prev(after)->y;
      g.mean += y;
      g.min = std::min(g.min, y);
      g.max = std::max(g.max, y);
    }
    g.mean /= static_cast<double>(runs.size());
    out.push_back(g);
  }
  return out;
}

std::string RenderComparePage(const std::vector<CompareRun>& runs, const std::string& page_dir) {
  const std::vector<Group> groups = MakeGroups(runs);
  std::vector<RunSummary> summaries;
  for (const CompareRun& run : runs) summaries.push_back(Summarize(run));
  const auto summary_of = [&](const CompareRun* run) -> const RunSummary& {
    return summaries[static_cast<size_t>(run - runs.data())];
  };

  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<title>Comparing " + std::to_string(runs.size()) + " run" + (runs.size() == 1 ? "" : "s") +
       "</title>\n";
  h += "<style>" + std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n";
  std::string presets;
  for (size_t i = 0; i < groups.size(); ++i) {
    presets += (i == 0 ? "" : i + 1 == groups.size() ? " and " : ", ") + groups[i].preset;
  }
  h += "<h1>Comparing " + std::to_string(runs.size()) + " run" + (runs.size() == 1 ? "" : "s") +
       " <small class=\"meta\">of " + HtmlEscape(presets) + "</small></h1>\n";
  int skipped = 0;
  for (const CompareRun& run : runs) skipped += run.skipped_lines;
  h += "<p class=\"meta\">Written " + HtmlEscape(UtcNow()) +
       " by scripts/compare.sh from each run's eval.jsonl.";
  if (skipped > 0) {
    h += " " + std::to_string(skipped) + " line" + (skipped == 1 ? "" : "s") +
         " of eval.jsonl did not parse and " + (skipped == 1 ? "was" : "were") + " skipped.";
  }
  h += "</p>\n";

  // One section of curves per env (returns of different envs do not share a scale).
  std::vector<std::string> envs;
  for (const Group& g : groups) {
    if (std::find(envs.begin(), envs.end(), g.env_id) == envs.end()) envs.push_back(g.env_id);
  }
  for (const std::string& env : envs) {
    std::vector<Group> here;
    for (const Group& g : groups) {
      if (g.env_id == env) here.push_back(g);
    }
    h += "<section class=\"curves\">\n<h2>Learning curves";
    if (!env.empty()) h += " <span class=\"env\">\xC2\xB7 " + HtmlEscape(env) + "</span>";
    h += "</h2>\n<div class=\"legend\">";
    for (const Group& g : here) {
      h += "<span>" + Swatch(g.color) + "<b>" + HtmlEscape(g.preset) + "</b> <small>(" +
           std::to_string(g.runs.size()) + " run" + (g.runs.size() == 1 ? "" : "s") +
           ")</small></span>";
    }
    h += "<span class=\"keys\">" + std::string(kLegendKeys) + "</span></div>\n";
    h += "<p class=\"how\">Every line is a <b>best evaluation mean so far</b>, not raw scores "
         "(the tables give the final ones): a thin line per run, with a dot at its last "
         "evaluation; for a preset of several runs, the mean across them and their lowest to "
         "highest as a band, drawn from where every run has been scored, each run holding its "
         "last value once it has stopped (a run stops at its goal). Wall time counts from each "
         "run's learner start.</p>\n";
    Plot plot;
    plot.title = "Best evaluation mean so far vs. environment steps";
    plot.x_label = "environment steps";
    plot.axis = CurveAxis::kEnvSteps;
    h += "<figure>" + RenderPlot(here, plot) + "</figure>\n";
    plot.title = "Best evaluation mean so far vs. wall time";
    plot.x_label = "wall time since the learner started";
    plot.axis = CurveAxis::kWallSeconds;
    h += "<figure>" + RenderPlot(here, plot) + "</figure>\n</section>\n";
  }

  // Groups.
  h += "<section>\n<h2>Presets</h2>\n<p class=\"how\">The mean over a preset's runs, and below it "
       "the lowest and the highest run.</p>\n<div class=\"scroll\"><table>\n<thead><tr>"
       "<th>preset</th><th>runs</th><th>evaluations</th><th>goal reached</th>"
       "<th>best mean</th><th>env steps at best</th><th>wall time at best</th>"
       "<th>final mean</th><th>goal first reached at</th></tr></thead>\n<tbody>\n";
  for (const Group& g : groups) {
    std::vector<double> best, best_steps, best_wall, final, goal_steps, goal_wall;
    int evaluations = 0, reached = 0;
    for (const CompareRun* run : g.runs) {
      const RunSummary& s = summary_of(run);
      evaluations += s.evaluations;
      best.push_back(s.best.mean);
      best_steps.push_back(static_cast<double>(s.best.env_steps));
      best_wall.push_back(s.best.wall_seconds);
      final.push_back(s.final.mean);
      if (s.goal_reached) {
        ++reached;
        goal_steps.push_back(static_cast<double>(s.first_goal.env_steps));
        goal_wall.push_back(s.first_goal.wall_seconds);
      }
    }
    h += "<tr class=\"group\"><td>" + Swatch(g.color) + HtmlEscape(g.preset) + "</td><td>" +
         std::to_string(g.runs.size()) + "</td><td>" + std::to_string(evaluations) + "</td>";
    if (std::isfinite(g.goal)) {
      h += std::string("<td") +
           (reached == static_cast<int>(g.runs.size()) ? " class=\"yes\"" : "") + ">" +
           std::to_string(reached) + " of " + std::to_string(g.runs.size()) +
           "<small>mean \xE2\x89\xA5 " + HtmlEscape(Format("%g", g.goal)) + "</small></td>";
    } else {
      h += std::string("<td>") + kDash + "</td>";
    }
    h += "<td>" + MeanRange(best, Score) + "</td><td>" + MeanRange(best_steps, Thousands) +
         "</td><td>" + MeanRange(best_wall, Duration) + "</td><td>" + MeanRange(final, Score) +
         "</td><td>";
    if (goal_steps.empty()) {
      h += kDash;
    } else {
      h += Thousands(Mean(goal_steps)) + " steps, " + Duration(Mean(goal_wall)) + "<small>";
      if (goal_steps.size() < g.runs.size()) {
        h += "the " + std::to_string(goal_steps.size()) + " that reached it";
      } else if (goal_steps.size() > 1) {
        h += "mean of " + std::to_string(goal_steps.size());
      }
      h += "</small>";
    }
    h += "</td></tr>\n";
  }
  h += "</tbody>\n</table></div>\n</section>\n";

  // Runs, by group.
  h += "<section>\n<h2>Runs</h2>\n<p class=\"how\">Best: the first evaluation with the highest "
       "mean; final: the evaluation of the last checkpoint. A run's name links to its "
       "report.</p>\n<div class=\"scroll\"><table>\n<thead><tr><th>run</th><th>seed</th>"
       "<th>evaluations</th><th>best mean</th><th>env steps at best</th><th>wall time at best</th>"
       "<th>final mean</th><th>last evaluation at</th><th>goal first reached at</th></tr>"
       "</thead>\n";
  for (const Group& g : groups) {
    h += "<tbody>\n<tr class=\"sub\"><th colspan=\"9\">" + Swatch(g.color) + HtmlEscape(g.preset) +
         "</th></tr>\n";
    for (const CompareRun* run : g.runs) {
      const RunSummary& s = summary_of(run);
      h += "<tr><td>" + RunName(*run, page_dir) + "</td><td>" +
           (run->seed >= 0 ? std::to_string(run->seed) : std::string(kDash)) + "</td><td>" +
           std::to_string(s.evaluations) + "</td><td>" + ScoreStd(s.best) + "</td><td>" +
           Thousands(static_cast<double>(s.best.env_steps)) + "</td><td>" +
           Duration(s.best.wall_seconds) + "</td><td>" + ScoreStd(s.final) + "</td><td>" +
           StepsAndTime(s.final) + "</td>";
      if (s.goal_reached) {
        h += "<td class=\"yes\">" + StepsAndTime(s.first_goal) + "</td>";
      } else if (std::isfinite(run->goal)) {
        h += "<td>not reached <small class=\"inline\">(\xE2\x89\xA5 " +
             HtmlEscape(Format("%g", run->goal)) + ")</small></td>";
      } else {
        h += std::string("<td>") + kDash + "</td>";
      }
      h += "</tr>\n";
    }
    h += "</tbody>\n";
  }
  h += "</table></div>\n</section>\n</main>\n</body>\n</html>\n";
  return h;
}

void WriteComparePage(const std::string& path, const std::vector<CompareRun>& runs) {
  std::string dir = fs::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  WriteFileAtomically(path, RenderComparePage(runs, dir), "compare page");
}

}  // namespace rl::tools
