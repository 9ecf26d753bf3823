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
#include "evaluator/plot.h"
#include "evaluator/svg_canvas.h"

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

constexpr char kDash[] = "\xE2\x80\x94";

// ---- Colours ----

// One colour per group, in order (none of them the goal's red).
constexpr plot::Colour kPalette[] = {plot::Colour::Hex(0x1f6feb), plot::Colour::Hex(0xbf3989),
                                     plot::Colour::Hex(0x1a7f37), plot::Colour::Hex(0xbc4c00),
                                     plot::Colour::Hex(0x8250df), plot::Colour::Hex(0x0a7f86),
                                     plot::Colour::Hex(0x9a6700), plot::Colour::Hex(0x57606a)};

// Plots with more runs than this name none of them at their ends (the lines' tooltips still do).
constexpr size_t kMaxRunLabels = 12;

// ---- Groups ----

struct Group {
  std::string preset;
  std::string env_id;
  double goal = kNaN;
  plot::Colour color;
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

// A group's curves against one axis: each run's best so far, and their combination.
struct GroupCurves {
  std::vector<std::vector<StepPoint>> runs;
  std::vector<GroupPoint> combined;
};

std::vector<plot::Point> ToPoints(const std::vector<StepPoint>& steps) {
  std::vector<plot::Point> points;
  for (const StepPoint& p : steps) points.push_back({p.x, p.y});
  return points;
}

// The chart: x from 0, y covering every value, 0 and the goals.
plot::ChartSpec PlotSpec(const std::vector<GroupCurves>& curves, const std::set<double>& goals,
                         const Plot& p) {
  double x_hi = 0, y_lo = 0, y_hi = 0;
  bool any = false;
  for (const GroupCurves& c : curves) {
    for (const std::vector<StepPoint>& run : c.runs) {
      for (const StepPoint& point : run) {
        x_hi = std::max(x_hi, point.x);
        y_lo = std::min(y_lo, point.y);
        y_hi = std::max(y_hi, point.y);
        any = true;
      }
    }
  }
  for (double g : goals) {
    y_lo = std::min(y_lo, g);
    y_hi = std::max(y_hi, g);
  }
  plot::ChartSpec spec;
  spec.width = p.width;
  spec.height = p.height;
  spec.title = p.title;
  spec.x_label = p.x_label;
  spec.y_label = "best evaluation mean so far";
  if (p.axis == CurveAxis::kWallSeconds) {
    const plot::TimeUnit unit = plot::PickTimeUnit(x_hi);
    spec.x_unit = unit.seconds;
    spec.x_label += " (" + unit.name + ")";
  } else {
    spec.x_format = plot::TickFormat::kCount;
  }
  spec.x_min = 0;
  spec.x_max = !any || x_hi <= 0 ? spec.x_unit : x_hi;
  spec.y_min = y_lo;
  spec.y_max = y_hi;
  spec.x_ticks = 8;
  spec.y_ticks = 6;
  return spec;
}

// The min-max band of a group of several runs.
void DrawBand(plot::Canvas* canvas, const plot::Chart& chart, const Group& g,
              const GroupCurves& c) {
  if (c.combined.empty() || g.runs.size() < 2) return;
  std::vector<plot::Point> hi, lo;
  for (const GroupPoint& p : c.combined) {
    hi.push_back({p.x, p.max});
    lo.push_back({p.x, p.min});
  }
  canvas->Path(chart.At(plot::StepBand(hi, lo)), true, plot::Paint::Fill(g.color, 0.14),
               {"band", g.preset + ": min to max of " + std::to_string(g.runs.size()) + " runs"});
}

// Each run thin (thick when alone) with a dot at its last evaluation, and the group's mean.
void DrawLines(plot::Canvas* canvas, const plot::Chart& chart, const Group& g, const GroupCurves& c,
               std::vector<plot::EndLabel>* labels) {
  const bool alone = g.runs.size() == 1;
  plot::Paint run_paint = plot::Paint::Stroke(g.color, alone ? 2.2 : 1);
  run_paint.stroke_opacity = alone ? 1 : 0.55;
  run_paint.round_joins = true;
  for (size_t ri = 0; ri < g.runs.size(); ++ri) {
    const std::vector<StepPoint>& run = c.runs[ri];
    if (run.empty()) continue;
    const std::string& label = g.runs[ri]->label;
    canvas->Path(chart.At(plot::StepCorners(ToPoints(run))), false, run_paint, {"run", label});
    const plot::Point end = chart.At(run.back().x, run.back().y);
    canvas->Circle(end, alone ? 3.5 : 2.5, plot::Paint::Fill(g.color),
                   {"", label + ": last evaluation"});
    labels->push_back({end, label, g.color});
  }
  if (alone || c.combined.empty()) return;
  std::vector<plot::Point> mean;
  for (const GroupPoint& p : c.combined) mean.push_back({p.x, p.mean});
  plot::Paint mean_paint = plot::Paint::Stroke(g.color, 2.6);
  mean_paint.round_joins = true;
  canvas->Path(chart.At(plot::StepCorners(mean)), false, mean_paint,
               {"mean", g.preset + ": mean of " + std::to_string(g.runs.size()) + " runs"});
}

std::string RenderPlot(const std::vector<Group>& groups, const Plot& p) {
  std::vector<GroupCurves> curves;
  std::set<double> goals;
  for (const Group& g : groups) {
    GroupCurves c;
    for (const CompareRun* run : g.runs) c.runs.push_back(BestSoFar(*run, p.axis));
    c.combined = CombineSteps(c.runs);
    curves.push_back(std::move(c));
    if (std::isfinite(g.goal)) goals.insert(g.goal);
  }
  plot::SvgCanvas canvas(p.width, p.height, p.title, plot::kTextColour);
  const plot::Chart chart(PlotSpec(curves, goals, p));
  chart.DrawFrame(&canvas);
  // Bands first, so that no band hides a line.
  for (size_t gi = 0; gi < groups.size(); ++gi) DrawBand(&canvas, chart, groups[gi], curves[gi]);
  std::vector<plot::EndLabel> labels;
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    DrawLines(&canvas, chart, groups[gi], curves[gi], &labels);
  }
  // Too many names to read: none (the lines' tooltips still name them).
  if (labels.size() <= kMaxRunLabels) plot::DrawEndLabels(&canvas, chart, std::move(labels));
  plot::Paint goal = plot::Paint::Stroke(plot::kGoalColour, 1.2);
  goal.dash = {6, 4};
  for (double g : goals) chart.DrawRule(&canvas, g, "goal " + Format("%g", g), goal, {"goal", ""});
  return canvas.Document();
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

std::string Swatch(plot::Colour color) {
  return "<span class=\"swatch\" style=\"background:" + color.ToHex() + "\"></span>";
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

// "<small>1,234 episodes</small>": the training episodes by `r`'s update, when the run's
// metrics tell them; else "".
std::string TrainingEpisodes(const CompareRun& run, const EvalRecord& r) {
  const std::optional<int64_t> episodes = evaluator::EpisodesAt(run.episodes, r.update);
  return episodes ? "<small>" + Thousands(*episodes) + " episodes</small>" : std::string();
}

// The line styles of the plots, for the legend (drawn by the CSS of .k).
constexpr char kLegendKeys[] =
    "<i class=\"k run\"></i>a run <i class=\"k mean\"></i>mean of a preset's runs "
    "<i class=\"k band\"></i>their lowest to highest <i class=\"k goal\"></i>goal";

std::string ScoreStd(const EvalRecord& r) {
  return Score(r.mean) + " <small class=\"inline\">\xC2\xB1 " + Score(r.std) + "</small>";
}

// The ensemble of `r` (ensemble_size > 0): "812.5 ± 40.1" and below it "5, updates 200,000 to
// 220,000" ("5 averaged, ..." for an average of weights).
std::string EnsembleCell(const EvalRecord& r) {
  return Score(r.ensemble_mean) + " <small class=\"inline\">\xC2\xB1 " + Score(r.ensemble_std) +
         "</small><small>" + std::to_string(r.ensemble_size) +
         (r.ensemble_by == "weights" ? " averaged" : "") + ", updates " +
         Thousands(static_cast<double>(r.ensemble_from)) + " to " +
         Thousands(static_cast<double>(r.update)) + "</small>";
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

// The summaries of the runs, by run.
class Summaries {
 public:
  explicit Summaries(const std::vector<CompareRun>& runs) : runs_(runs) {
    for (const CompareRun& run : runs) summaries_.push_back(Summarize(run));
  }
  const RunSummary& of(const CompareRun* run) const {
    return summaries_[static_cast<size_t>(run - runs_.data())];
  }

 private:
  const std::vector<CompareRun>& runs_;
  std::vector<RunSummary> summaries_;
};

// The document's head, the title and the line under it.
std::string PageHeader(const std::vector<CompareRun>& runs, const std::vector<Group>& groups) {
  const std::string count = std::to_string(runs.size()) + " run" + (runs.size() == 1 ? "" : "s");
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<title>Comparing " + count + "</title>\n";
  h += "<style>" + std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n";
  std::string presets;
  for (size_t i = 0; i < groups.size(); ++i) {
    presets += (i == 0 ? "" : i + 1 == groups.size() ? " and " : ", ") + groups[i].preset;
  }
  h += "<h1>Comparing " + count + " <small class=\"meta\">of " + HtmlEscape(presets) +
       "</small></h1>\n";
  int skipped = 0;
  for (const CompareRun& run : runs) skipped += run.skipped_lines;
  h += "<p class=\"meta\">Written " + HtmlEscape(UtcNow()) +
       " by scripts/compare.sh from each run's eval.jsonl.";
  if (skipped > 0) {
    h += " " + std::to_string(skipped) + " line" + (skipped == 1 ? "" : "s") +
         " of eval.jsonl did not parse and " + (skipped == 1 ? "was" : "were") + " skipped.";
  }
  return h + "</p>\n";
}

// The legend and the two plots of the groups of one env.
std::string CurvesSection(const std::string& env, const std::vector<Group>& here) {
  std::string h = "<section class=\"curves\">\n<h2>Learning curves";
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
  return h + "<figure>" + RenderPlot(here, plot) + "</figure>\n</section>\n";
}

// One row of the presets table: the mean over the group's runs, with their range.
std::string PresetRow(const Group& g, const Summaries& summaries) {
  std::vector<double> best, best_steps, best_wall, final, goal_steps, goal_wall;
  int evaluations = 0, reached = 0;
  for (const CompareRun* run : g.runs) {
    const RunSummary& s = summaries.of(run);
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
  std::string h = "<tr class=\"group\"><td>" + Swatch(g.color) + HtmlEscape(g.preset) +
                  "</td><td>" + std::to_string(g.runs.size()) + "</td><td>" +
                  std::to_string(evaluations) + "</td>";
  if (std::isfinite(g.goal)) {
    h += std::string("<td") + (reached == static_cast<int>(g.runs.size()) ? " class=\"yes\"" : "") +
         ">" + std::to_string(reached) + " of " + std::to_string(g.runs.size()) +
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
  return h + "</td></tr>\n";
}

std::string PresetsSection(const std::vector<Group>& groups, const Summaries& summaries) {
  std::string h =
      "<section>\n<h2>Presets</h2>\n<p class=\"how\">The mean over a preset's runs, and below "
      "it the lowest and the highest run.</p>\n<div class=\"scroll\"><table>\n<thead><tr>"
      "<th>preset</th><th>runs</th><th>evaluations</th><th>goal reached</th>"
      "<th>best mean</th><th>env steps at best</th><th>wall time at best</th>"
      "<th>final mean</th><th>goal first reached at</th></tr></thead>\n<tbody>\n";
  for (const Group& g : groups) h += PresetRow(g, summaries);
  return h + "</tbody>\n</table></div>\n</section>\n";
}

// The runs, by group.
std::string RunsSection(const std::vector<Group>& groups, const Summaries& summaries,
                        const std::string& page_dir) {
  bool ensembles = false;
  for (const Group& g : groups) {
    for (const CompareRun* run : g.runs)
      ensembles |= summaries.of(run).best_ensemble.ensemble_size > 0;
  }
  std::string h =
      "<section>\n<h2>Runs</h2>\n<p class=\"how\">Best: the first evaluation with the highest "
      "mean; final: the evaluation of the last checkpoint. A run's name links to its "
      "report.";
  if (ensembles) {
    h += " Best ensemble: the highest mean of a checkpoint and those before it played as one, by "
         "their mean action or (averaged) as the network of their mean weights (how many, and "
         "their updates, below it), on the same episodes.";
  }
  h += "</p>\n<div class=\"scroll\"><table>\n<thead><tr><th>run</th><th>seed</th>"
       "<th>evaluations</th><th>best mean</th><th>env steps at best</th><th>wall time at best</th>"
       "<th>final mean</th><th>last evaluation at</th><th>goal first reached at</th>";
  if (ensembles) h += "<th>best ensemble</th>";
  h += "</tr></thead>\n";
  for (const Group& g : groups) {
    h += "<tbody>\n<tr class=\"sub\"><th colspan=\"" + std::to_string(ensembles ? 10 : 9) + "\">" +
         Swatch(g.color) + HtmlEscape(g.preset) + "</th></tr>\n";
    for (const CompareRun* run : g.runs) {
      const RunSummary& s = summaries.of(run);
      h += "<tr><td>" + RunName(*run, page_dir) + "</td><td>" +
           (run->seed >= 0 ? std::to_string(run->seed) : std::string(kDash)) + "</td><td>" +
           std::to_string(s.evaluations) + "</td><td>" + ScoreStd(s.best) + "</td><td>" +
           Thousands(static_cast<double>(s.best.env_steps)) + TrainingEpisodes(*run, s.best) +
           "</td><td>" + Duration(s.best.wall_seconds) + "</td><td>" + ScoreStd(s.final) +
           "</td><td>" + StepsAndTime(s.final) + "</td>";
      if (s.goal_reached) {
        h += "<td class=\"yes\">" + StepsAndTime(s.first_goal) + "</td>";
      } else if (std::isfinite(run->goal)) {
        h += "<td>not reached <small class=\"inline\">(\xE2\x89\xA5 " +
             HtmlEscape(Format("%g", run->goal)) + ")</small></td>";
      } else {
        h += std::string("<td>") + kDash + "</td>";
      }
      if (ensembles) {
        h += "<td>" +
             (s.best_ensemble.ensemble_size > 0 ? EnsembleCell(s.best_ensemble)
                                                : std::string(kDash)) +
             "</td>";
      }
      h += "</tr>\n";
    }
    h += "</tbody>\n";
  }
  return h + "</table></div>\n</section>\n";
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
  run.episodes = evaluator::LoadActorEpisodes((fs::path(dir) / "metrics.jsonl").string()).by_update;
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
    if (r.ensemble_size > 0 &&
        (s.best_ensemble.ensemble_size == 0 || r.ensemble_mean > s.best_ensemble.ensemble_mean)) {
      s.best_ensemble = r;
    }
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
  Summaries summaries(runs);
  std::string h = PageHeader(runs, groups);
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
    h += CurvesSection(env, here);
  }
  h += PresetsSection(groups, summaries);
  h += RunsSection(groups, summaries, page_dir);
  h += "</main>\n</body>\n</html>\n";
  return h;
}

void WriteComparePage(const std::string& path, const std::vector<CompareRun>& runs) {
  std::string dir = fs::path(path).parent_path().string();
  if (dir.empty()) dir = ".";
  WriteFileAtomically(path, RenderComparePage(runs, dir), "compare page");
}

}  // namespace rl::tools
