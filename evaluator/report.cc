#include "evaluator/report.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "common/atomic_file.h"
#include "common/text_format.h"
#include "evaluator/flat_json.h"
#include "evaluator/learning_curve.h"
#include "evaluator/training_curves.h"

namespace rl::evaluator {
namespace {

// ---- Files ----

[[noreturn]] void ThrowIo(const std::string& what, const std::string& path) {
  throw std::runtime_error("cannot " + what + " '" + path + "': " + std::strerror(errno));
}

// ---- HTML pieces ----

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

}  // namespace

std::string ToJson(const EvalRecord& r) {
  std::string s = "{\"checkpoint\": ";
  AppendJsonString(&s, r.checkpoint);
  s += ", \"update\": " + std::to_string(r.update);
  s += ", \"env_steps\": " + std::to_string(r.env_steps);
  s += ", \"wall_seconds\": " + JsonNumber(r.wall_seconds);
  s += ", \"mean\": " + JsonNumber(r.mean);
  s += ", \"std\": " + JsonNumber(r.std);
  s += ", \"min\": " + JsonNumber(r.min);
  s += ", \"max\": " + JsonNumber(r.max);
  s += ", \"episodes\": " + std::to_string(r.episodes);
  s += ", \"eval_seconds\": " + JsonNumber(r.eval_seconds);
  if (r.value_steps > 0) {
    s += ", \"value_steps\": " + std::to_string(r.value_steps);
    s += ", \"value_estimate\": " + JsonNumber(r.value_estimate);
    s += ", \"value_return\": " + JsonNumber(r.value_return);
    s += ", \"value_correlation\": " +
         (r.value_correlation ? JsonNumber(*r.value_correlation) : std::string("null"));
  }
  if (r.second_episodes > 0) {
    s += ", \"second_mean\": " + JsonNumber(r.second_mean);
    s += ", \"second_std\": " + JsonNumber(r.second_std);
    s += ", \"second_episodes\": " + std::to_string(r.second_episodes);
  }
  s += "}";
  return s;
}

bool ParseJson(const std::string& line, EvalRecord* record) {
  JsonObject obj;
  if (!ParseFlatJsonObject(line, &obj)) return false;
  const auto name = obj.find("checkpoint");
  if (name == obj.end() || !name->second.is_string) return false;
  const std::optional<int64_t> update = GetJsonInt(obj, "update");
  const std::optional<double> mean = GetJsonDouble(obj, "mean");
  if (!update || !mean) return false;
  EvalRecord r;
  r.checkpoint = name->second.text;
  r.update = *update;
  r.mean = *mean;
  r.env_steps = GetJsonInt(obj, "env_steps").value_or(0);
  r.wall_seconds = GetJsonDouble(obj, "wall_seconds").value_or(0);
  r.std = GetJsonDouble(obj, "std").value_or(0);
  r.min = GetJsonDouble(obj, "min").value_or(r.mean);
  r.max = GetJsonDouble(obj, "max").value_or(r.mean);
  r.episodes = static_cast<int>(GetJsonInt(obj, "episodes").value_or(0));
  r.eval_seconds = GetJsonDouble(obj, "eval_seconds").value_or(0);
  r.value_steps = GetJsonInt(obj, "value_steps").value_or(0);
  if (r.value_steps > 0) {
    r.value_estimate = GetJsonDouble(obj, "value_estimate").value_or(0);
    r.value_return = GetJsonDouble(obj, "value_return").value_or(0);
    const std::optional<double> c = GetJsonDouble(obj, "value_correlation");
    if (c && std::isfinite(*c)) r.value_correlation = *c;
  }
  r.second_episodes = static_cast<int>(GetJsonInt(obj, "second_episodes").value_or(0));
  if (r.second_episodes > 0) {
    r.second_mean = GetJsonDouble(obj, "second_mean").value_or(0);
    r.second_std = GetJsonDouble(obj, "second_std").value_or(0);
  }
  *record = std::move(r);
  return true;
}

void AppendJsonLine(const std::string& path, const EvalRecord& record) {
  const std::string line = ToJson(record) + "\n";
  std::FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) ThrowIo("open", path);
  const bool written = std::fwrite(line.data(), 1, line.size(), f) == line.size();
  const bool flushed = written && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  const int saved_errno = errno;
  std::fclose(f);
  errno = saved_errno;
  if (!flushed) ThrowIo("append to", path);
}

std::vector<EvalRecord> LoadJsonLines(const std::string& path, int* skipped_lines) {
  std::vector<EvalRecord> records;
  int skipped = 0;
  std::ifstream in(path);
  std::string line;
  while (in && std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    EvalRecord r;
    if (ParseJson(line, &r)) {
      records.push_back(std::move(r));
    } else {
      ++skipped;
    }
  }
  if (skipped_lines != nullptr) *skipped_lines = skipped;
  return records;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void WriteReport(const std::string& dir, const std::vector<EvalRecord>& records,
                 const ReportInfo& info) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create '" + dir + "': " + ec.message());
  const bool has_goal = std::isfinite(info.goal);

  // Best mean (the first checkpoint to reach it), the first to reach the goal, the latest.
  const EvalRecord* best = nullptr;
  const EvalRecord* first_goal = nullptr;
  const EvalRecord* latest = nullptr;
  for (const EvalRecord& r : records) {
    if (best == nullptr || r.mean > best->mean) best = &r;
    if (has_goal && r.mean >= info.goal &&
        (first_goal == nullptr || r.update < first_goal->update)) {
      first_goal = &r;
    }
    if (latest == nullptr || r.update >= latest->update) latest = &r;
  }

  // The two learning curves.
  std::vector<CurvePoint> by_steps, by_time;
  for (const EvalRecord& r : records) {
    by_steps.push_back({static_cast<double>(r.env_steps), r.mean, r.std, r.min, r.max});
    by_time.push_back({r.wall_seconds, r.mean, r.std, r.min, r.max});
  }
  CurveStyle style;
  style.goal = has_goal ? info.goal : std::nan("");
  style.title = "Evaluation return vs. environment steps";
  style.x_label = "environment steps";
  style.x_kind = XAxisKind::kCount;
  WriteFileAtomically(dir + "/" + kCurveEnvSteps, RenderLearningCurveSvg(by_steps, style));
  style.title = "Evaluation return vs. wall time";
  style.x_label = "wall time since the learner started";
  style.x_kind = XAxisKind::kSeconds;
  WriteFileAtomically(dir + "/" + kCurveWallTime, RenderLearningCurveSvg(by_time, style));

  // The training curves, from the metrics the monitor keeps.
  std::vector<TrainingSeries> training;
  if (!info.metrics_file.empty()) training = LoadTrainingSeries(info.metrics_file);
  for (TrainingSeries& s : training) {
    CurveStyle ts;
    ts.title = s.title;
    ts.x_label = "time since the launch";
    ts.y_label = s.y_label;
    ts.x_kind = XAxisKind::kSeconds;
    ts.goal = std::nan("");
    ts.width = 560;
    ts.height = 300;
    WriteFileAtomically(dir + "/" + s.file, RenderLearningCurveSvg(std::move(s.points), ts));
  }

  // Title.
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
       std::to_string(records.size()) + " checkpoint" + (records.size() == 1 ? "" : "s") +
       " scored";
  if (info.checkpoints_skipped > 0) {
    h += ", " + std::to_string(info.checkpoints_skipped) + " skipped (superseded)";
  }
  if (info.checkpoints_refused > 0) {
    h += ", " + std::to_string(info.checkpoints_refused) + " refused";
  }
  h += ".";
  if (!info.eval_settings.empty()) h += " " + HtmlEscape(info.eval_settings);
  h += "</p>\n";

  // Summary cards.
  h += "<section class=\"summary\">\n<h2>Summary</h2>\n<div class=\"cards\">\n";
  h += "<div class=\"card\"><div class=\"label\">Goal</div><div class=\"value\">";
  if (!has_goal) {
    h += "<span class=\"badge no\">none set</span>";
  } else if (first_goal != nullptr) {
    h += "<span class=\"badge yes\">reached</span></div><div class=\"detail\">mean \xE2\x89\xA5 " +
         HtmlEscape(Format("%g", info.goal)) + " first at update " + Thousands(first_goal->update) +
         ", " + Thousands(first_goal->env_steps) + " env steps, " +
         Duration(first_goal->wall_seconds);
  } else {
    h += "<span class=\"badge no\">not reached</span></div><div class=\"detail\">goal: mean "
         "\xE2\x89\xA5 " +
         HtmlEscape(Format("%g", info.goal));
  }
  h += "</div></div>\n";
  h += "<div class=\"card\"><div class=\"label\">Best mean return</div>";
  if (best != nullptr) {
    h += "<div class=\"value\">" + Score(best->mean) + " <small>\xC2\xB1 " + Score(best->std) +
         "</small></div><div class=\"detail\">update " + Thousands(best->update) + ", " +
         Thousands(best->env_steps) + " env steps, " + Duration(best->wall_seconds) + "</div>";
    // The second metric of the best checkpoint that has one (a tie with a later checkpoint
    // leaves the later one without).
    const EvalRecord* second = nullptr;
    for (const EvalRecord& r : records) {
      if (r.second_episodes > 0 && (second == nullptr || r.mean > second->mean)) second = &r;
    }
    if (second != nullptr) {
      h += "<div class=\"detail\">second metric (update " + Thousands(second->update) +
           "): " + Score(second->second_mean) + " \xC2\xB1 " + Score(second->second_std) +
           " over " + std::to_string(second->second_episodes) + " episodes</div>";
    }
  } else {
    h += "<div class=\"value\">\xE2\x80\x94</div><div class=\"detail\">no checkpoint scored "
         "yet</div>";
  }
  h += "</div>\n";
  h += "<div class=\"card\"><div class=\"label\">Latest checkpoint</div>";
  if (latest != nullptr) {
    h += "<div class=\"value\">" + Score(latest->mean) + " <small>\xC2\xB1 " + Score(latest->std) +
         "</small></div><div class=\"detail\">update " + Thousands(latest->update) + ", " +
         Thousands(latest->env_steps) + " env steps, " + Duration(latest->wall_seconds) + "</div>";
  } else {
    h += "<div class=\"value\">\xE2\x80\x94</div>";
  }
  h += "</div>\n</div>\n</section>\n";

  // Learning curves.
  h += "<section>\n<h2>Learning curves</h2>\n";
  h += "<figure><img src=\"" + std::string(kCurveEnvSteps) +
       "\" alt=\"evaluation mean return with a band of one standard deviation against "
       "environment steps\" width=\"720\" height=\"380\"></figure>\n";
  h += "<figure><img src=\"" + std::string(kCurveWallTime) +
       "\" alt=\"evaluation mean return with a band of one standard deviation against wall "
       "time\" width=\"720\" height=\"380\"></figure>\n";
  h += "</section>\n";

  // Training curves.
  if (!training.empty()) {
    h += "<section>\n<h2>Training</h2>\n<p>What the processes reported while the run went "
         "(metrics.jsonl): whether it learns, stalls or diverges, and why.</p>\n";
    for (const TrainingSeries& s : training) {
      h += "<figure><img src=\"" + HtmlEscape(s.file) + "\" alt=\"" + HtmlEscape(s.title) +
           " against time\" width=\"560\" height=\"300\"></figure>\n";
    }
    h += "</section>\n";
  }

  // The greedy policy at work.
  if (!info.video_file.empty()) {
    h += "<section>\n<h2>Greedy policy</h2>\n<figure><video src=\"" + HtmlEscape(info.video_file) +
         "\" controls autoplay loop muted playsinline width=\"480\"></video><figcaption>" +
         HtmlEscape(info.video_caption) + "</figcaption></figure>\n</section>\n";
  }

  // What the network sees.
  if (!info.frames_file.empty()) {
    h += "<section>\n<h2>Camera frames</h2>\n<figure><img src=\"" + HtmlEscape(info.frames_file) +
         "\" alt=\"a grid of camera frames and network inputs, one row per greedy "
         "episode\"><figcaption>" +
         HtmlEscape(info.frames_caption) + "</figcaption></figure>\n</section>\n";
  }

  // How the network tells states apart.
  if (!info.tsne_file.empty()) {
    h += "<section>\n<h2>Last hidden layer (t-SNE)</h2>\n<figure><img src=\"" +
         HtmlEscape(info.tsne_file) +
         "\" alt=\"a t-SNE map of the network's last hidden layer in states of greedy episodes, "
         "coloured by value, with some of their frames\"><figcaption>" +
         HtmlEscape(info.tsne_caption) + "</figcaption></figure>\n</section>\n";
  }

  // Table of every checkpoint, newest first.
  h += "<section>\n<h2>Checkpoints</h2>\n";
  if (records.empty()) {
    h += "<p class=\"empty\">No checkpoint scored yet.</p>\n";
  } else {
    std::vector<const EvalRecord*> rows;
    for (const EvalRecord& r : records) rows.push_back(&r);
    std::stable_sort(rows.begin(), rows.end(), [](const EvalRecord* a, const EvalRecord* b) {
      return a->update > b->update;
    });
    double bar_scale = has_goal ? info.goal : 0;
    for (const EvalRecord* r : rows) bar_scale = std::max(bar_scale, r->mean);
    const bool has_values = std::any_of(records.begin(), records.end(),
                                        [](const EvalRecord& r) { return r.value_steps > 0; });
    if (has_values) {
      h += "<p>Q is the network's mean value estimate of the actions taken in the evaluation "
           "episodes; G is the mean discounted return that followed them (van Hasselt et al. "
           "2016: Q well above G is overestimation); r is the correlation of the two across the "
           "steps (near 0: the network cannot tell good states from bad ones).</p>\n";
    }
    const bool has_second = !info.second_name.empty();
    if (has_second) {
      h += "<p>Second metric (new best checkpoints only): " + HtmlEscape(info.second_name) +
           ".</p>\n";
    }
    h += "<div class=\"scroll\"><table>\n<thead><tr><th>checkpoint</th><th>update</th>"
         "<th>env steps</th><th>wall time</th><th>mean</th><th>std</th><th>min</th><th>max</th>"
         "<th>episodes</th><th>eval time</th>";
    if (has_values) h += "<th>Q</th><th>G</th><th>r</th>";
    if (has_second) h += "<th>second metric</th>";
    h += "</tr></thead>\n<tbody>\n";
    for (const EvalRecord* r : rows) {
      std::string cls;
      if (r == best) cls += "best";
      if (has_goal && r->mean >= info.goal) cls += cls.empty() ? "goal" : " goal";
      const double bar = bar_scale > 0 ? std::clamp(r->mean / bar_scale, 0.0, 1.0) * 100.0 : 0.0;
      h += cls.empty() ? "<tr>" : "<tr class=\"" + cls + "\">";
      h += "<td>" + HtmlEscape(r->checkpoint) + "</td>";
      h += "<td>" + Thousands(r->update) + "</td>";
      h += "<td>" + Thousands(r->env_steps) + "</td>";
      h += "<td>" + Duration(r->wall_seconds) + "</td>";
      h += "<td class=\"mean\"><span class=\"bar\" style=\"width:" + Format("%.1f", bar) +
           "%\"></span>" + Score(r->mean) + "</td>";
      h += "<td>" + Score(r->std) + "</td>";
      h += "<td>" + Format("%g", r->min) + "</td>";
      h += "<td>" + Format("%g", r->max) + "</td>";
      h += "<td>" + std::to_string(r->episodes) + "</td>";
      h += "<td>" + Format("%.2f s", r->eval_seconds) + "</td>";
      if (has_values && r->value_steps > 0) {
        h += "<td>" + Score(r->value_estimate) + "</td><td>" + Score(r->value_return) +
             "</td><td>" +
             (r->value_correlation ? Format("%.2f", *r->value_correlation) : "\xE2\x80\x94") +
             "</td>";
      } else if (has_values) {
        h += "<td></td><td></td><td></td>";
      }
      if (has_second) {
        h += "<td>" +
             (r->second_episodes > 0 ? Score(r->second_mean) + " \xC2\xB1 " + Score(r->second_std) +
                                           " (" + std::to_string(r->second_episodes) + ")"
                                     : std::string()) +
             "</td>";
      }
      h += "</tr>\n";
    }
    h += "</tbody>\n</table></div>\n";
  }
  h += "</section>\n";

  // Processes the launch script restarted (crashes, kills).
  if (!info.restarts_file.empty()) {
    std::ifstream in(info.restarts_file);
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
    if (n > 0) {
      std::string summary;
      for (const auto& [role, k] : by_role) {
        summary += (summary.empty() ? "" : ", ") + role + " " + std::to_string(k);
      }
      h += "<section>\n<h2>Restarts</h2>\n<p>" + std::to_string(n) + " process restart" +
           (n == 1 ? "" : "s") + " (" + HtmlEscape(summary) +
           "): the launch script restarted each after it exited (status above 128: killed by "
           "signal status - 128), but those whose node was lost (a Slurm node down).</p>\n<div "
           "class=\"scroll\"><table>\n<thead><tr><th>time</th>"
           "<th>process</th><th>exit status</th><th>restart</th></tr></thead>\n<tbody>\n" +
           rows + "</tbody>\n</table></div>\n</section>\n";
    }
  }

  // The run's config.
  h += "<section>\n<h2>Run config</h2>\n<pre>" +
       HtmlEscape(info.run_config.empty() ? "(none given)" : info.run_config) +
       "</pre>\n</section>\n";
  h += "</main>\n</body>\n</html>\n";
  WriteFileAtomically(dir + "/" + kReportIndex, h);
}

}  // namespace rl::evaluator
