// Command-line and INI options of our processes (Boost.Program_options).
//
// Every process reads the same preset file (--config configs/cartpole.ini). Keys at the top of
// the file apply to every process that knows them; keys in a section [actor], [replay],
// [learner] or [evaluator] apply to that process only; an unknown key in a process's own section
// and a section of no process (a misspelled [lerner]) are errors (a typo must not pass silently).
// The command line wins over the file. `PROCESS --list-options` prints the names a preset may
// set for the process, which the launcher checks whole presets against (launch/preset.h).
#pragma once

#include <boost/program_options.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "common/lcm_bus.h"

namespace rl {

namespace po = boost::program_options;

// The sections a preset may have: one per process that reads presets.
inline constexpr const char* kConfigSections[] = {"actor", "replay", "learner", "evaluator"};

// Options every process has: --config, --run-id, --key-file, --lcm-url, --lcm-bulk-url,
// --lcm-samples-url, --max-message-age, --max-clock-skew, and --help and --list-options.
struct CommonOptions {
  std::string config_file;
  int64_t run_id = 0;
  std::string key_file;  // the run's secret key (common/message_auth.h); empty: no MACs
  std::string lcm_url = kDefaultLcmUrl;
  std::string lcm_bulk_url = kDefaultLcmBulkUrl;
  std::string lcm_samples_url = kDefaultLcmSamplesUrl;
  // The freshness window, seconds (common/lcm_bus.h: why these defaults).
  double max_message_age = kDefaultMaxMessageAgeMicros * 1e-6;
  double max_clock_skew = kDefaultMaxClockSkewMicros * 1e-6;

  // Reads the key file, if any (throws std::runtime_error when it is unfit), and checks the
  // window (std::invalid_argument naming the option when it is not in (0, 1 day]).
  BusConfig MakeBusConfig(const std::string& sender) const;
};

void AddCommonOptions(po::options_description* desc, CommonOptions* common);

// Parses argv and the --config file into *vm and notifies the bound variables. The command line
// wins over the file, and in the file a key of `role`'s section wins over the same top-level
// key; a section that is neither `role` nor one of kConfigSections is refused. Returns false when
// --help or --list-options was asked for (the help text, or the names of the options a preset may
// set, one a line: every option of `desc` but help, config and list-options, has been printed).
// Throws on bad options, with a message that names the option.
bool ParseOptions(int argc, char** argv, const std::string& role, const std::string& usage,
                  const po::options_description& desc, po::variables_map* vm);

/// Whether option `name` of `desc` is on the command line itself, not only in the --config file
/// (a preset's key may set what only a command line should switch on).
bool OnCommandLine(int argc, char** argv, const po::options_description& desc,
                   const std::string& name);

/// Throws std::runtime_error("option --NAME does not apply: <why>") for the first of `names`
/// that was given (on the command line or in the config file) rather than left at its default:
/// options of the algorithm or exploration a run did not choose are refused, not ignored.
void RefuseGiven(const po::variables_map& vm, const std::vector<std::string>& names,
                 const std::string& why);

// Runs body() and turns an exception into "<program>: error: <what>" on stderr and exit code 2.
int RunMain(const char* program, int (*body)(int, char**), int argc, char** argv);

}  // namespace rl
