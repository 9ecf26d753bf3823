// The compare page: the evaluation curves of several run folders overlaid on one self-contained
// HTML page (inline SVG, no scripts, no network fetches), with a table per run and per group.
//
// Runs of the same preset (config.ini's "# Run of preset 'NAME'" line, written by
// scripts/launch.sh) form a group. The curves show each run's best evaluation mean so far (a step
// function of env steps or wall time, held after the run's last evaluation: a run stops when it
// reaches its goal); per group the mean across its runs and their min-max band, drawn where every
// run of the group has been scored; each run also as a thin line up to its last evaluation. Runs
// of different envs get separate plots (their returns do not share a scale).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "evaluator/report.h"
#include "evaluator/training_curves.h"

namespace rl::tools {

/// One run folder as the compare page sees it.
struct CompareRun {
  std::string dir;     // the folder as given
  std::string label;   // its name on the page: the folder's name, or more of its path when two
                       // runs share a name (set by MakeLabelsUnique)
  std::string preset;  // the preset launch.sh ran ("cartpole")
  std::string env_id;  // the config's top-level "env = ..." ("" when it has none)
  double goal = 0;     // the run's goal; NaN when config.ini names none
  int64_t seed = -1;   // the run seed; -1 when config.ini names none
  std::vector<evaluator::EvalRecord> records;  // eval.jsonl, in file order; never empty
  int skipped_lines = 0;                       // eval.jsonl lines that did not parse
  // The actors' episodes by learner update (metrics.jsonl); empty when the folder has none.
  std::vector<evaluator::EpisodesAtUpdate> episodes;
};

/// Reads `dir`/config.ini (preset, env, goal, seed), `dir`/eval.jsonl and, when there is one,
/// `dir`/metrics.jsonl (the training episodes). Throws
/// std::runtime_error with a one-line message that names `dir` when it is not a folder, has no
/// config.ini or no eval.jsonl, when config.ini has no "# Run of preset" line, or when eval.jsonl
/// has no evaluation that parses.
CompareRun LoadCompareRun(const std::string& dir);

/// Gives every run a distinct label: its folder's name, with as many parent folders in front as
/// it takes to tell runs of the same name apart. Folders given twice (the same canonical path)
/// keep the same label: the caller refuses them.
void MakeLabelsUnique(std::vector<CompareRun>* runs);

/// The numbers of the tables for one run.
struct RunSummary {
  int evaluations = 0;
  evaluator::EvalRecord best;        // the first evaluation with the highest mean
  evaluator::EvalRecord final;       // the evaluation of the highest update (the last, on ties)
  bool goal_reached = false;         // some evaluation's mean is at least the goal
  evaluator::EvalRecord first_goal;  // the first (lowest update) to reach it; unset if not
  // The first evaluation with the highest ensemble mean (evaluator --ensemble); its
  // ensemble_size is 0 when no evaluation has an ensemble.
  evaluator::EvalRecord best_ensemble;
};

/// Summarizes `run` (whose records are not empty).
RunSummary Summarize(const CompareRun& run);

/// Which x a curve is drawn against.
enum class CurveAxis { kEnvSteps, kWallSeconds };

/// A point of a step function: the value holds from x until the next point's x.
struct StepPoint {
  double x = 0;
  double y = 0;
};

/// The run's best evaluation mean so far against `axis`: one point per evaluation that raised
/// it (and the first), in x order; evaluations with a non-finite x or mean are left out.
std::vector<StepPoint> BestSoFar(const CompareRun& run, CurveAxis axis);

/// A point of a group's curve: mean, min and max over the group's runs of their value at x.
struct GroupPoint {
  double x = 0;
  double mean = 0;
  double min = 0;
  double max = 0;
};

/// The group's curve from the step functions of its runs: a point at every x where some run's
/// value changes, from the first x at which every run has a value (the latest of the runs' first
/// x) on; a run's value is held after its last point. Empty when `runs` is empty or one of them
/// is.
std::vector<GroupPoint> CombineSteps(const std::vector<std::vector<StepPoint>>& runs);

/// The whole page for `runs` (at least one, labels unique): groups in the order their first run
/// appears, runs in the order given. Each run's name links to its report/index.html, relative to
/// `page_dir` (the folder the page goes to), when that file exists; `page_dir` empty: no links.
std::string RenderComparePage(const std::vector<CompareRun>& runs, const std::string& page_dir);

/// Writes RenderComparePage(runs, folder of `path`) to `path` atomically (rl::WriteFileAtomically).
/// Throws std::runtime_error naming the file on an I/O error.
void WriteComparePage(const std::string& path, const std::vector<CompareRun>& runs);

}  // namespace rl::tools
