#include "evaluator/report.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <vector>

#include "common/atomic_file.h"
#include "common/text_format.h"
#include "evaluator/learning_curve.h"
#include "evaluator/training_curves.h"

namespace rl::evaluator {
namespace {

std::string Format(const char* fmt, double v) { return FormatDouble(fmt, v); }

constexpr char kCss[] = R"css(
:root { --fg: #24292f; --muted: #57606a; --line: #d0d7de; --soft: #f6f8fa;
        --accent: #1f6feb; --good: #1a7f37; --bad: #cf222e; }
* { box-sizing: border-box; }
body { margin: 0; background: #eef1f4; color: var(--fg);
       font: 15px/1.5 -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; }
main { max-width: 1040px; margin: 0 auto; padding: 28px 20px 48px; }
h1 { margin: 0 0 2px; font-size: 26px; }
h1 .run { color: var(--muted); font-weight: 400; }
h2 { font-size: 18px; margin: 0 0 12px; }
.meta { color: var(--muted); margin: 0 0 20px; font-size: 13px; }
section { background: #fff; border: 1px solid var(--line); border-radius: 8px;
          padding: 18px 20px; margin: 0 0 18px; }
.cards { display: grid; grid-template-columns: repeat(auto-fit, minmax(210px, 1fr)); gap: 12px; }
.card { background: var(--soft); border-radius: 6px; padding: 12px 14px; }
.card .label { color: var(--muted); font-size: 12px; text-transform: uppercase;
               letter-spacing: .04em; }
.card .value { font-size: 24px; font-weight: 600; }
.card .detail { color: var(--muted); font-size: 13px; }
.badge { display: inline-block; border-radius: 999px; padding: 2px 12px; font-size: 14px;
         font-weight: 600; color: #fff; }
.badge.yes { background: var(--good); }
.badge.no { background: var(--muted); }
figure { margin: 0 0 12px; text-align: center; }
figure img { max-width: 100%; height: auto; border: 1px solid var(--line); border-radius: 6px; }
table { width: 100%; border-collapse: collapse; font-size: 13px; }
th, td { padding: 5px 8px; border-bottom: 1px solid var(--line); text-align: right;
         white-space: nowrap; }
th { background: var(--soft); position: sticky; top: 0; }
th:first-child, td:first-child { text-align: left; }
tr.best td { background: #ddf4ff; font-weight: 600; }
tr.goal td:first-child::after { content: " \2713"; color: var(--good); }
td.mean { position: relative; }
td.mean .bar { position: absolute; left: 0; top: 3px; bottom: 3px; background: var(--accent);
               opacity: .14; border-radius: 2px; }
.scroll { max-height: 560px; overflow: auto; }
pre { background: var(--soft); border-radius: 6px; padding: 12px; overflow: auto;
      font: 12.5px/1.45 ui-monospace, "SFMono-Regular", Menlo, Consolas, monospace; margin: 0; }
.empty { color: var(--muted); }
)css";

// The records the summary and the table point out.
struct Highlights {
  const EvalRecord* best = nullptr;        // the best mean (the first checkpoint to reach it)
  const EvalRecord* first_goal = nullptr;  // the first (lowest update) at the goal
  const EvalRecord* latest = nullptr;      // the highest update
  const EvalRecord* second = nullptr;      // the best with a second metric
  const EvalRecord* ensemble = nullptr;    // the best ensemble (highest ensemble mean)
};

Highlights FindHighlights(const std::vector<EvalRecord>& records, double goal) {
  Highlights h;
  for (const EvalRecord& r : records) {
    if (h.best == nullptr || r.mean > h.best->mean) h.best = &r;
    if (std::isfinite(goal) && r.mean >= goal &&
        (h.first_goal == nullptr || r.update < h.first_goal->update)) {
      h.first_goal = &r;
    }
    if (h.latest == nullptr || r.update >= h.latest->update) h.latest = &r;
    // A tie with a later checkpoint leaves the later one without a second metric.
    if (r.second_episodes > 0 && (h.second == nullptr || r.mean > h.second->mean)) h.second = &r;
    if (r.ensemble_size > 0 &&
        (h.ensemble == nullptr || r.ensemble_mean > h.ensemble->ensemble_mean)) {
      h.ensemble = &r;
    }
  }
  return h;
}

// "ensemble" or, for an average of weights (EvaluatorConfig::ensemble_by), "average".
std::string EnsembleWord(const EvalRecord& r) {
  return r.ensemble_by == "weights" ? "average" : "ensemble";
}

// curve_env_steps.svg and curve_wall_time.svg, with the ensembles' means as a second line named
// by the kind and size of the last record's ensemble ("ensemble of 5", "average of 5") when some
// record has one.
void WriteLearningCurves(const std::string& dir, const std::vector<EvalRecord>& records,
                         double goal) {
  std::vector<CurvePoint> by_steps, by_time;
  CurveOverlay ensembles_by_steps, ensembles_by_time;
  for (const EvalRecord& r : records) {
    by_steps.push_back({static_cast<double>(r.env_steps), r.mean, r.std, r.min, r.max});
    by_time.push_back({r.wall_seconds, r.mean, r.std, r.min, r.max});
    if (r.ensemble_size > 0) {
      ensembles_by_steps.label = EnsembleWord(r) + " of " + std::to_string(r.ensemble_size);
      ensembles_by_steps.points.push_back({static_cast<double>(r.env_steps), r.ensemble_mean});
      ensembles_by_time.points.push_back({r.wall_seconds, r.ensemble_mean});
    }
  }
  ensembles_by_time.label = ensembles_by_steps.label;
  CurveStyle style;
  style.goal = std::isfinite(goal) ? goal : std::nan("");
  style.title = "Evaluation return vs. environment steps";
  style.x_label = "environment steps";
  style.x_kind = XAxisKind::kCount;
  WriteFileAtomically(dir + "/" + kCurveEnvSteps,
                      RenderLearningCurveSvg(by_steps, style, std::move(ensembles_by_steps)));
  style.title = "Evaluation return vs. wall time";
  style.x_label = "wall time since the learner started";
  style.x_kind = XAxisKind::kSeconds;
  WriteFileAtomically(dir + "/" + kCurveWallTime,
                      RenderLearningCurveSvg(by_time, style, std::move(ensembles_by_time)));
}

// The training curves from the metrics the monitor keeps; returns what was drawn.
std::vector<TrainingSeries> WriteTrainingCurves(const std::string& dir,
                                                const std::string& metrics_file) {
  std::vector<TrainingSeries> training;
  if (!metrics_file.empty()) training = LoadTrainingSeries(metrics_file);
  for (TrainingSeries& s : training) {
    CurveStyle style;
    style.title = s.title;
    style.x_label = "time since the launch";
    style.y_label = s.y_label;
    style.x_kind = XAxisKind::kSeconds;
    style.goal = std::nan("");
    style.width = 560;
    style.height = 300;
    WriteFileAtomically(dir + "/" + s.file, RenderLearningCurveSvg(std::move(s.points), style));
  }
  return training;
}

// The document's head, the title and the line under it.
std::string Header(const ReportInfo& info, size_t records) {
  std::string run;
  if (!info.run_name.empty() && info.run_id != 0) {
    run = "run " + info.run_name + " (id " + std::to_string(info.run_id) + ")";
  } else if (!info.run_name.empty()) {
    run = "run " + info.run_name;
  } else if (info.run_id != 0) {
    run = "run id " + std::to_string(info.run_id);
  }
  const std::string title = info.env_id + (run.empty() ? "" : " \xC2\xB7 " + run);
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<title>" + HtmlEscape(title) + " \xE2\x80\x94 evaluation</title>\n";
  h += "<style>" + std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n";
  h += "<h1>" + HtmlEscape(info.env_id);
  if (!run.empty()) h += " <span class=\"run\">\xC2\xB7 " + HtmlEscape(run) + "</span>";
  h += "</h1>\n";
  h += "<p class=\"meta\">Evaluation report, updated " + HtmlEscape(UtcNow()) + ". " +
       std::to_string(records) + " checkpoint" + (records == 1 ? "" : "s") + " scored";
  if (info.checkpoints_skipped > 0) {
    h += ", " + std::to_string(info.checkpoints_skipped) + " skipped (superseded)";
  }
  if (info.checkpoints_refused > 0) {
    h += ", " + std::to_string(info.checkpoints_refused) + " refused";
  }
  h += ".";
  if (!info.eval_settings.empty()) h += " " + HtmlEscape(info.eval_settings);
  h += "</p>\n";
  return h;
}

// "update 1,200, 4,800 env steps, 12 s", with ", 310 training episodes" before the time when
// the run's metrics tell them.
std::string Where(const EvalRecord& r, const std::vector<EpisodesAtUpdate>& episodes) {
  const std::optional<int64_t> trained = EpisodesAt(episodes, r.update);
  return "update " + Thousands(r.update) + ", " + Thousands(r.env_steps) + " env steps, " +
         (trained ? Thousands(*trained) + " training episodes, " : std::string()) +
         Duration(r.wall_seconds);
}

// A card's value: the mean and its std.
std::string MeanValue(const EvalRecord& r) {
  return "<div class=\"value\">" + Score(r.mean) + " <small>\xC2\xB1 " + Score(r.std) +
         "</small></div>";
}

// The summary cards: the goal, the best mean, the latest checkpoint.
std::string SummarySection(const Highlights& hl, const ReportInfo& info,
                           const std::vector<EpisodesAtUpdate>& episodes) {
  std::string h = "<section class=\"summary\">\n<h2>Summary</h2>\n<div class=\"cards\">\n";
  h += "<div class=\"card\"><div class=\"label\">Goal</div><div class=\"value\">";
  const std::string goal = HtmlEscape(Format("%g", info.goal));
  if (!std::isfinite(info.goal)) {
    h += "<span class=\"badge no\">none set</span>";
  } else if (hl.first_goal != nullptr) {
    h += "<span class=\"badge yes\">reached</span></div><div class=\"detail\">mean \xE2\x89\xA5 " +
         goal + " first at " + Where(*hl.first_goal, episodes);
  } else {
    h += "<span class=\"badge no\">not reached</span></div><div class=\"detail\">goal: mean "
         "\xE2\x89\xA5 " +
         goal;
  }
  h += "</div></div>\n<div class=\"card\"><div class=\"label\">Best mean return</div>";
  if (hl.best != nullptr) {
    h += MeanValue(*hl.best) + "<div class=\"detail\">" + Where(*hl.best, episodes) + "</div>";
    if (hl.second != nullptr) {
      h += "<div class=\"detail\">second metric (update " + Thousands(hl.second->update) +
           "): " + Score(hl.second->second_mean) + " \xC2\xB1 " + Score(hl.second->second_std) +
           " over " + std::to_string(hl.second->second_episodes) + " episodes</div>";
    }
  } else {
    h += "<div class=\"value\">\xE2\x80\x94</div><div class=\"detail\">no checkpoint scored "
         "yet</div>";
  }
  if (hl.ensemble != nullptr) {
    const EvalRecord& e = *hl.ensemble;
    const bool weights = e.ensemble_by == "weights";
    h += "</div>\n<div class=\"card\"><div class=\"label\">Best " + EnsembleWord(e) + "</div>";
    h += "<div class=\"value\">" + Score(e.ensemble_mean) + " <small>\xC2\xB1 " +
         Score(e.ensemble_std) + "</small></div><div class=\"detail\">" +
         (weights ? "the mean weights of " : "the mean action of ") +
         std::to_string(e.ensemble_size) + " checkpoints, updates " + Thousands(e.ensemble_from) +
         " to " + Thousands(e.update) + " (" + Thousands(e.env_steps) + " env steps, " +
         Duration(e.wall_seconds) + ")" +
         (weights ? std::string("; kept as ") + kBestAverageFile : std::string()) + "</div>";
  }
  h += "</div>\n<div class=\"card\"><div class=\"label\">Latest checkpoint</div>";
  if (hl.latest != nullptr) {
    h += MeanValue(*hl.latest) + "<div class=\"detail\">" + Where(*hl.latest, episodes) + "</div>";
  } else {
    h += "<div class=\"value\">\xE2\x80\x94</div>";
  }
  h += "</div>\n</div>\n</section>\n";
  return h;
}

// The learning curves and, with metrics, the training curves.
std::string CurvesSections(const std::vector<TrainingSeries>& training) {
  std::string h = "<section>\n<h2>Learning curves</h2>\n";
  h += "<figure><img src=\"" + std::string(kCurveEnvSteps) +
       "\" alt=\"evaluation mean return with a band of one standard deviation against "
       "environment steps\" width=\"720\" height=\"380\"></figure>\n";
  h += "<figure><img src=\"" + std::string(kCurveWallTime) +
       "\" alt=\"evaluation mean return with a band of one standard deviation against wall "
       "time\" width=\"720\" height=\"380\"></figure>\n";
  h += "</section>\n";
  if (training.empty()) return h;
  h += "<section>\n<h2>Training</h2>\n<p>What the processes reported while the run went "
       "(metrics.jsonl): whether it learns, stalls or diverges, and why.</p>\n";
  for (const TrainingSeries& s : training) {
    h += "<figure><img src=\"" + HtmlEscape(s.file) + "\" alt=\"" + HtmlEscape(s.title) +
         " against time\" width=\"560\" height=\"300\"></figure>\n";
  }
  h += "</section>\n";
  return h;
}

// A section of one figure with its caption.
std::string FigureSection(const std::string& heading, const std::string& media,
                          const std::string& caption) {
  return "<section>\n<h2>" + heading + "</h2>\n<figure>" + media + "<figcaption>" +
         HtmlEscape(caption) + "</figcaption></figure>\n</section>\n";
}

// The greedy policy at work, what the network sees and how it tells states apart.
std::string MediaSections(const ReportInfo& info) {
  std::string h;
  if (!info.video_file.empty()) {
    h += FigureSection("Greedy policy",
                       "<video src=\"" + HtmlEscape(info.video_file) +
                           "\" controls autoplay loop muted playsinline width=\"480\"></video>",
                       info.video_caption);
  }
  if (!info.frames_file.empty()) {
    h += FigureSection("Camera frames",
                       "<img src=\"" + HtmlEscape(info.frames_file) +
                           "\" alt=\"a grid of camera frames and network inputs, one row per "
                           "greedy episode\">",
                       info.frames_caption);
  }
  if (!info.tsne_file.empty()) {
    h += FigureSection("Last hidden layer (t-SNE)",
                       "<img src=\"" + HtmlEscape(info.tsne_file) +
                           "\" alt=\"a t-SNE map of the network's last hidden layer in states of "
                           "greedy episodes, coloured by value, with some of their frames\">",
                       info.tsne_caption);
  }
  return h;
}

// The q-quantile (0 to 1) of the finite `values`, interpolated between the two nearest order
// statistics; NaN when there is none.
double Quantile(std::vector<double> values, double q) {
  std::erase_if(values, [](double v) { return !std::isfinite(v); });
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const double at = q * static_cast<double>(values.size() - 1);
  const auto below = static_cast<size_t>(at);
  const size_t above = std::min(below + 1, values.size() - 1);
  return values[below] + (at - static_cast<double>(below)) * (values[above] - values[below]);
}

// One row of the checkpoint table.
std::string CheckpointRow(const EvalRecord& r, const Highlights& hl, const ReportInfo& info,
                          const std::vector<EpisodesAtUpdate>& episodes, double bar_scale,
                          bool has_values, bool has_returns, bool has_actions, bool has_second,
                          bool has_ensemble) {
  std::string cls;
  if (&r == hl.best) cls += "best";
  if (std::isfinite(info.goal) && r.mean >= info.goal) cls += cls.empty() ? "goal" : " goal";
  const double bar = bar_scale > 0 ? std::clamp(r.mean / bar_scale, 0.0, 1.0) * 100.0 : 0.0;
  std::string h = cls.empty() ? "<tr>" : "<tr class=\"" + cls + "\">";
  h += "<td>" + HtmlEscape(r.checkpoint) + "</td><td>" + Thousands(r.update) + "</td><td>" +
       Thousands(r.env_steps) + "</td>";
  if (!episodes.empty()) {
    const std::optional<int64_t> trained = EpisodesAt(episodes, r.update);
    h += "<td>" + (trained ? Thousands(*trained) : std::string()) + "</td>";
  }
  h += "<td>" + Duration(r.wall_seconds) + "</td>";
  h += "<td class=\"mean\"><span class=\"bar\" style=\"width:" + Format("%.1f", bar) +
       "%\"></span>" + Score(r.mean) + "</td>";
  h += "<td>" + Score(r.std) + "</td><td>" + Format("%g", r.min) + "</td>";
  if (has_returns) {
    h += r.returns.empty() ? std::string("<td></td><td></td>")
                           : "<td>" + Score(Quantile(r.returns, 0.1)) + "</td><td>" +
                                 Score(Quantile(r.returns, 0.5)) + "</td>";
  }
  h += "<td>" + Format("%g", r.max) + "</td><td>" + std::to_string(r.episodes) + "</td><td>" +
       Format("%.2f s", r.eval_seconds) + "</td>";
  if (has_values && r.value_steps > 0) {
    h += "<td>" + Score(r.value_estimate) + "</td><td>" + Score(r.value_return) + "</td><td>" +
         (r.value_correlation ? Format("%.2f", *r.value_correlation) : "\xE2\x80\x94") + "</td>";
  } else if (has_values) {
    h += "<td></td><td></td><td></td>";
  }
  if (has_actions) {
    std::string mean_action;
    for (double a : r.action_mean)
      mean_action += (mean_action.empty() ? "" : ", ") + Format("%.2f", a);
    h += "<td>" + mean_action + "</td>";
  }
  if (has_second) {
    h += "<td>" +
         (r.second_episodes > 0 ? Score(r.second_mean) + " \xC2\xB1 " + Score(r.second_std) + " (" +
                                      std::to_string(r.second_episodes) + ")"
                                : std::string()) +
         "</td>";
  }
  if (has_ensemble) {
    h += "<td>" +
         (r.ensemble_size > 0 ? Score(r.ensemble_mean) + " \xC2\xB1 " + Score(r.ensemble_std) +
                                    " (" + std::to_string(r.ensemble_size) + ")"
                              : std::string()) +
         "</td>";
  }
  return h + "</tr>\n";
}

// The table of every checkpoint, newest first.
std::string CheckpointsSection(const std::vector<EvalRecord>& records, const Highlights& hl,
                               const ReportInfo& info,
                               const std::vector<EpisodesAtUpdate>& episodes) {
  std::string h = "<section>\n<h2>Checkpoints</h2>\n";
  if (records.empty()) return h + "<p class=\"empty\">No checkpoint scored yet.</p>\n</section>\n";
  std::vector<const EvalRecord*> rows;
  for (const EvalRecord& r : records) rows.push_back(&r);
  std::stable_sort(rows.begin(), rows.end(),
                   [](const EvalRecord* a, const EvalRecord* b) { return a->update > b->update; });
  double bar_scale = std::isfinite(info.goal) ? info.goal : 0;
  for (const EvalRecord* r : rows) bar_scale = std::max(bar_scale, r->mean);
  if (!episodes.empty()) {
    h += "<p>Training episodes: the episodes the actors had finished when the learner reached the "
         "checkpoint's update (from metrics.jsonl, to within its rows' spacing).</p>\n";
  }
  const bool has_values = std::any_of(records.begin(), records.end(),
                                      [](const EvalRecord& r) { return r.value_steps > 0; });
  if (has_values) {
    h += "<p>Q is the network's mean value estimate of the actions taken in the evaluation "
         "episodes; G is the mean discounted return that followed them (van Hasselt et al. "
         "2016: Q well above G is overestimation); r is the correlation of the two across the "
         "steps (near 0: the network cannot tell good states from bad ones).</p>\n";
  }
  const bool has_returns = std::any_of(records.begin(), records.end(),
                                       [](const EvalRecord& r) { return !r.returns.empty(); });
  if (has_returns) {
    h += "<p>10 % and median: the returns that a tenth and a half of the evaluation episodes fell "
         "below. A mean well under its median comes from a few failed episodes, a low median "
         "from a shortfall in most of them.</p>\n";
  }
  const bool has_actions = std::any_of(records.begin(), records.end(),
                                       [](const EvalRecord& r) { return !r.action_mean.empty(); });
  if (has_actions) {
    h += "<p>Mean action: each component of the action, in the env's order, averaged over every "
         "step of the evaluation episodes (CarRacing: steer, gas and brake; with pedals=1 steer "
         "and the pedal, gas above 0, brake below); what the policy does.</p>\n";
  }
  const bool has_second = !info.second_name.empty();
  if (has_second) {
    h +=
        "<p>Second metric (new best checkpoints only): " + HtmlEscape(info.second_name) + ".</p>\n";
  }
  const bool has_ensemble = hl.ensemble != nullptr;
  if (has_ensemble && hl.ensemble->ensemble_by == "weights") {
    h += "<p>Average: the network whose weights are the mean of the checkpoint's and the ones' "
         "before it (their count in brackets), scored on the same episodes.</p>\n";
  } else if (has_ensemble) {
    h += "<p>Ensemble: the mean action of the checkpoint and the ones before it (their count in "
         "brackets), scored on the same episodes.</p>\n";
  }
  h += "<div class=\"scroll\"><table>\n<thead><tr><th>checkpoint</th><th>update</th>"
       "<th>env steps</th>";
  if (!episodes.empty()) h += "<th>training episodes</th>";
  h += "<th>wall time</th><th>mean</th><th>std</th><th>min</th>";
  if (has_returns) h += "<th>10 %</th><th>median</th>";
  h += "<th>max</th><th>eval episodes</th><th>eval time</th>";
  if (has_values) h += "<th>Q</th><th>G</th><th>r</th>";
  if (has_actions) h += "<th>mean action</th>";
  if (has_second) h += "<th>second metric</th>";
  if (has_ensemble) h += "<th>" + EnsembleWord(*hl.ensemble) + "</th>";
  h += "</tr></thead>\n<tbody>\n";
  for (const EvalRecord* r : rows) {
    h += CheckpointRow(*r, hl, info, episodes, bar_scale, has_values, has_returns, has_actions,
                       has_second, has_ensemble);
  }
  return h + "</tbody>\n</table></div>\n</section>\n";
}

// Processes the launch script restarted (crashes, kills); empty when there were none.
std::string RestartsSection(const std::string& restarts_file) {
  if (restarts_file.empty()) return "";
  std::ifstream in(restarts_file);
  std::string rows;
  std::map<std::string, int> by_role;
  int n = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string time, role, status_word, code, restart_word, count;
    if (!(fields >> time >> role >> status_word >> code >> restart_word >> count)) continue;
    ++n;
    ++by_role[role];
    // "TIME ROLE status CODE lost 0": its node left the Slurm job; not restarted.
    const std::string restart = restart_word == "lost" ? "node lost" : count;
    rows += "<tr><td>" + HtmlEscape(time) + "</td><td>" + HtmlEscape(role) + "</td><td>" +
            HtmlEscape(code) + "</td><td>" + HtmlEscape(restart) + "</td></tr>\n";
  }
  if (n == 0) return "";
  std::string summary;
  for (const auto& [role, k] : by_role) {
    summary += (summary.empty() ? "" : ", ") + role + " " + std::to_string(k);
  }
  return "<section>\n<h2>Restarts</h2>\n<p>" + std::to_string(n) + " process restart" +
         (n == 1 ? "" : "s") + " (" + HtmlEscape(summary) +
         "): the launch script restarted each after it exited (status above 128: killed by "
         "signal status - 128), but those whose node was lost (a Slurm node down).</p>\n<div "
         "class=\"scroll\"><table>\n<thead><tr><th>time</th>"
         "<th>process</th><th>exit status</th><th>restart</th></tr></thead>\n<tbody>\n" +
         rows + "</tbody>\n</table></div>\n</section>\n";
}

std::string CaptionPath(const std::string& media_path) { return media_path + ".caption"; }

// Which version of a media file a caption is of: its size and modification time (ns); "" when
// it is not a regular file.
std::string MediaStamp(const std::string& media_path) {
  struct stat st {};
  if (::stat(media_path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return {};
  const long long ns =
      static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
  return std::to_string(st.st_size) + " " + std::to_string(ns);
}

}  // namespace

void WriteCaption(const std::string& media_path, const std::string& caption) {
  const std::string stamp = MediaStamp(media_path);
  if (stamp.empty()) throw std::runtime_error("no media file " + media_path + " to caption");
  WriteFileAtomically(CaptionPath(media_path), stamp + "\n" + caption, "caption");
}

std::string ReadCaption(const std::string& media_path) {
  const std::string stamp = MediaStamp(media_path);
  if (stamp.empty()) return {};
  std::ifstream in(CaptionPath(media_path), std::ios::binary);
  std::string first;
  if (!std::getline(in, first) || first != stamp) return {};
  std::ostringstream caption;
  caption << in.rdbuf();
  return caption.str();
}

void WriteReport(const std::string& dir, const std::vector<EvalRecord>& records,
                 const ReportInfo& info) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create '" + dir + "': " + ec.message());
  WriteLearningCurves(dir, records, info.goal);
  const std::vector<TrainingSeries> training = WriteTrainingCurves(dir, info.metrics_file);

  const Highlights highlights = FindHighlights(records, info.goal);
  const std::vector<EpisodesAtUpdate> episodes = LoadActorEpisodes(info.metrics_file).by_update;
  std::string h = Header(info, records.size());
  h += SummarySection(highlights, info, episodes);
  h += CurvesSections(training);
  h += MediaSections(info);
  h += CheckpointsSection(records, highlights, info, episodes);
  h += RestartsSection(info.restarts_file);
  h += "<section>\n<h2>Run config</h2>\n<pre>" +
       HtmlEscape(info.run_config.empty() ? "(none given)" : info.run_config) +
       "</pre>\n</section>\n";
  h += "</main>\n</body>\n</html>\n";
  WriteFileAtomically(dir + "/" + kReportIndex, h);
}

}  // namespace rl::evaluator
