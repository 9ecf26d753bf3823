// compare: one HTML page overlaying the evaluation curves of several run folders, grouped by
// preset, with a table per run and per group (tools/compare_runs.h). scripts/compare.sh wraps it.
#include <boost/program_options.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "common/options.h"
#include "tools/compare_runs.h"

namespace {

int Main(int argc, char** argv) {
  namespace po = boost::program_options;
  std::string out = "compare.html";
  std::vector<std::string> dirs;
  po::options_description desc("Options");
  desc.add_options()                                                             //
      ("help,h", "show this help")                                               //
      ("out", po::value(&out)->default_value(out), "the HTML file to write")     //
      ("run", po::value(&dirs)->composing(), "a run folder (also positional)");  //
  po::positional_options_description positional;
  positional.add("run", -1);
  po::variables_map vm;
  po::store(po::command_line_parser(argc, argv).options(desc).positional(positional).run(), vm);
  po::notify(vm);
  if (vm.count("help") != 0) {
    std::cout << "Usage: compare [--out FILE] RUN_DIR...\n"
                 "Writes one self-contained HTML page overlaying the evaluation curves of the "
                 "runs (eval.jsonl), grouped by preset, with a table per run and per group.\n"
              << desc;
    return 0;
  }
  if (dirs.empty()) throw std::runtime_error("no run folder given (see --help)");

  std::vector<rl::tools::CompareRun> runs;
  std::set<std::string> seen;
  for (const std::string& dir : dirs) {
    std::error_code ec;
    const std::string canonical = std::filesystem::weakly_canonical(dir, ec).string();
    if (!seen.insert(ec ? dir : canonical).second) {
      throw std::runtime_error(dir + ": given twice");
    }
    runs.push_back(rl::tools::LoadCompareRun(dir));
  }
  rl::tools::MakeLabelsUnique(&runs);
  rl::tools::WriteComparePage(out, runs);
  std::set<std::string> presets;
  int evaluations = 0;
  for (const rl::tools::CompareRun& run : runs) {
    presets.insert(run.preset);
    evaluations += static_cast<int>(run.records.size());
  }
  std::printf("compare: wrote %s: %zu run%s of %zu preset%s, %d evaluations\n", out.c_str(),
              runs.size(), runs.size() == 1 ? "" : "s", presets.size(),
              presets.size() == 1 ? "" : "s", evaluations);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("compare", Main, argc, argv); }
