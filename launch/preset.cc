#include "launch/preset.h"

#include <boost/program_options.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "launch/launch_options.h"
#include "launch/proc.h"

namespace rl::launch {
namespace {

namespace po = boost::program_options;

// Levenshtein distance, for "did you mean" hints.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// " (did you mean 'NAME'?)" for the nearest of `names` when it is close to `name`, else "".
std::string Nearest(const std::string& name, const std::set<std::string>& names,
                    const char* quote_open, const char* quote_close) {
  const std::string* best = nullptr;
  size_t best_distance = 0;
  for (const std::string& candidate : names) {
    const size_t d = EditDistance(name, candidate);
    if (best == nullptr || d < best_distance) {
      best = &candidate;
      best_distance = d;
    }
  }
  if (best == nullptr || best_distance > std::max<size_t>(2, name.size() / 4)) return "";
  return std::string(" (did you mean ") + quote_open + *best + quote_close + "?)";
}

}  // namespace

Preset Preset::Read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw LaunchError("cannot read the preset " + path);
  std::stringstream text;
  text << in.rdbuf();
  return Parse(text.str(), path);
}

Preset Preset::Parse(const std::string& text, const std::string& path) {
  Preset preset;
  preset.path_ = path;
  std::istringstream in(text);
  po::options_description none;
  po::parsed_options parsed(&none);
  try {
    parsed = po::parse_config_file(in, none, /*allow_unregistered=*/true);
  } catch (const po::error& e) {
    throw LaunchError("preset " + path + ": " + e.what());
  }
  for (const po::option& opt : parsed.options) {
    PresetEntry entry;
    const size_t dot = opt.string_key.find('.');
    if (dot != std::string::npos) {
      entry.section = opt.string_key.substr(0, dot);
      entry.key = opt.string_key.substr(dot + 1);
    } else {
      entry.key = opt.string_key;
    }
    if (!opt.value.empty()) entry.value = opt.value.front();
    preset.entries_.push_back(std::move(entry));
  }
  return preset;
}

std::optional<std::string> Preset::Find(const std::string& section, const std::string& key) const {
  std::optional<std::string> found;
  for (const PresetEntry& e : entries_) {
    if (e.section == section && e.key == key) found = e.value;
  }
  return found;
}

OptionNames ListOptionNames(const std::string& bin_dir, const std::vector<std::string>& sections) {
  OptionNames names;
  for (const std::string& section : sections) {
    const std::string program = bin_dir + "/" + section;
    std::string listed;
    try {
      listed = RunAndCapture({program, "--list-options"});
    } catch (const std::exception& e) {
      throw LaunchError("cannot ask " + program + " for its options: " + e.what());
    }
    std::istringstream in(listed);
    for (std::string name; std::getline(in, name);) {
      if (!name.empty()) names[section].insert(name);
    }
  }
  return names;
}

void CheckPreset(const Preset& preset, const OptionNames& known) {
  std::set<std::string> sections, top_level = LauncherKeys();
  for (const auto& [section, names] : known) {
    sections.insert(section);
    top_level.insert(names.begin(), names.end());
  }
  for (const PresetEntry& e : preset.entries()) {
    if (e.section.empty()) {
      if (top_level.count(e.key) == 0) {
        throw LaunchError("preset " + preset.path() + ": unknown top-level key '" + e.key +
                          "': no process has that option" + Nearest(e.key, top_level, "'", "'"));
      }
      continue;
    }
    const auto it = known.find(e.section);
    if (it == known.end()) {
      throw LaunchError("preset " + preset.path() + ": unknown section [" + e.section + "] (key '" +
                        e.key + "')" + Nearest(e.section, sections, "[", "]") +
                        "; the sections are [actor], [replay], [learner] and [evaluator]");
    }
    if (it->second.count(e.key) == 0) {
      throw LaunchError("preset " + preset.path() + ": unknown key '" + e.key + "' in section [" +
                        e.section + "]: the " + e.section + " has no such option" +
                        Nearest(e.key, it->second, "'", "'"));
    }
  }
}

}  // namespace rl::launch
