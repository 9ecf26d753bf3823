#include "common/options.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <set>
#include <stdexcept>
#include <utility>

namespace rl {
namespace {

bool IsConfigSection(const std::string& name) {
  for (const char* section : kConfigSections) {
    if (name == section) return true;
  }
  return false;
}

}  // namespace

BusConfig CommonOptions::MakeBusConfig(const std::string& sender) const {
  BusConfig c;
  c.url = lcm_url;
  c.bulk_url = lcm_bulk_url;
  c.samples_url = lcm_samples_url;
  c.run_id = run_id;
  c.sender = sender;
  // A day bounds the window far above any use and keeps the microseconds far from overflow.
  for (const auto& [name, seconds] : {std::pair{"max-message-age", max_message_age},
                                      std::pair{"max-clock-skew", max_clock_skew}}) {
    if (!(seconds > 0 && seconds <= 86400)) {
      throw std::invalid_argument(std::string("--") + name + " must be in (0, 86400] seconds");
    }
  }
  c.max_message_age = static_cast<int64_t>(max_message_age * 1e6);
  c.max_clock_skew = static_cast<int64_t>(max_clock_skew * 1e6);
  if (!key_file.empty()) c.key = ReadKeyFile(key_file);
  return c;
}

void AddCommonOptions(po::options_description* desc, CommonOptions* common) {
  desc->add_options()                         //
      ("help,h", "print this help and exit")  //
      ("list-options",
       "print the names of the options a preset may set for this process, one a line, and "
       "exit")  //
      ("config", po::value(&common->config_file),
       "INI preset (top-level keys and the keys of this process's section)")  //
      ("run-id", po::value(&common->run_id)->default_value(common->run_id),
       "id of the run; messages of other runs are dropped")  //
      ("key-file", po::value(&common->key_file),
       "the run's secret key (32 bytes, mode 600): every message is signed with it, and "
       "received ones without its MAC are dropped")  //
      ("lcm-url", po::value(&common->lcm_url)->default_value(common->lcm_url),
       "LCM URL of the main port (small, high-rate messages)")  //
      ("lcm-bulk-url", po::value(&common->lcm_bulk_url)->default_value(common->lcm_bulk_url),
       "LCM URL of the bulk port (weights)")  //
      ("lcm-samples-url",
       po::value(&common->lcm_samples_url)->default_value(common->lcm_samples_url),
       "LCM URL of the samples port (the replay's sample replies to the learner); the bulk "
       "port's URL shares the bulk port")  //
      ("max-message-age",
       po::value(&common->max_message_age)->default_value(common->max_message_age),
       "seconds a message may be old (its header time against its arrival here) before it is "
       "dropped as stale; covers network delay and clock differences between hosts")  //
      ("max-clock-skew", po::value(&common->max_clock_skew)->default_value(common->max_clock_skew),
       "seconds a message's header time may be ahead of this host's clock before it is dropped as "
       "stale");
}

bool ParseOptions(int argc, char** argv, const std::string& role, const std::string& usage,
                  const po::options_description& desc, po::variables_map* vm) {
  po::store(po::parse_command_line(argc, argv, desc), *vm);
  if (vm->count("help")) {
    std::cout << usage << "\n\n" << desc << "\n";
    return false;
  }
  if (vm->count("list-options")) {
    for (const auto& option : desc.options()) {
      const std::string& name = option->long_name();
      if (name != "help" && name != "config" && name != "list-options") std::cout << name << "\n";
    }
    return false;
  }
  if (vm->count("config")) {
    const std::string path = (*vm)["config"].as<std::string>();
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open config file '" + path + "'");
    // Read every key, keep those of our section and the top-level ones we know; a key of our
    // section wins over the same top-level key (e.g. an [evaluator] env without the training-only
    // pipeline options).
    po::parsed_options parsed = po::parse_config_file(in, desc, /*allow_unregistered=*/true);
    po::parsed_options kept(&desc);
    const std::string prefix = role + ".";
    std::set<std::string> in_section;
    for (po::option& opt : parsed.options) {
      const std::string& key = opt.string_key;
      if (const size_t dot = key.find('.'); dot != std::string::npos) {
        const std::string section = key.substr(0, dot);
        if (section != role && !IsConfigSection(section)) {
          throw std::runtime_error("config file '" + path + "': unknown section [" + section +
                                   "] (key '" + key.substr(dot + 1) +
                                   "'); the sections are [actor], [replay], [learner] and "
                                   "[evaluator]");
        }
      }
      if (key.rfind(prefix, 0) != 0) continue;
      opt.string_key = key.substr(prefix.size());
      if (desc.find_nothrow(opt.string_key, false) == nullptr) {
        throw std::runtime_error("config file '" + path + "': unknown key '" + opt.string_key +
                                 "' in section [" + role + "]");
      }
      opt.unregistered = false;
      in_section.insert(opt.string_key);
      kept.options.push_back(opt);
    }
    for (const po::option& opt : parsed.options) {
      const std::string& key = opt.string_key;
      if (key.find('.') == std::string::npos && !opt.unregistered && !in_section.count(key)) {
        kept.options.push_back(opt);
      }
    }
    po::store(kept, *vm);
  }
  po::notify(*vm);
  return true;
}

bool OnCommandLine(int argc, char** argv, const po::options_description& desc,
                   const std::string& name) {
  const po::parsed_options parsed = po::parse_command_line(argc, argv, desc);
  return std::any_of(parsed.options.begin(), parsed.options.end(),
                     [&](const po::option& opt) { return opt.string_key == name; });
}

void RefuseGiven(const po::variables_map& vm, const std::vector<std::string>& names,
                 const std::string& why) {
  for (const std::string& name : names) {
    auto it = vm.find(name);
    if (it != vm.end() && !it->second.defaulted()) {
      throw std::runtime_error("option --" + name + " does not apply: " + why);
    }
  }
}

int RunMain(const char* program, int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return 2;
  }
}

}  // namespace rl
