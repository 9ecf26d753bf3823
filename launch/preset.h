// A preset (configs/NAME.ini, or a run's config.ini) as the launcher reads it: the same parser
// the processes use (Boost.Program_options' INI reader: '#' starts a comment anywhere on a line),
// and a check of every key against the options the processes know, so that a misspelled section
// or key stops the launch before anything starts instead of being ignored.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace rl::launch {

/// One "key = value" of a preset; `section` is empty for the keys above the first section.
struct PresetEntry {
  std::string section;
  std::string key;
  std::string value;
};

class Preset {
 public:
  /// Reads and parses `path`. Throws LaunchError naming the file when it cannot be read or a line
  /// is not "key = value", "[section]", a comment or blank.
  static Preset Read(const std::string& path);
  /// Parses `text` as the file `path` holds.
  static Preset Parse(const std::string& text, const std::string& path);

  const std::string& path() const { return path_; }
  const std::vector<PresetEntry>& entries() const { return entries_; }
  /// The value of `key` in `section` ("" for the top level), the last one when given twice.
  std::optional<std::string> Find(const std::string& section, const std::string& key) const;

 private:
  std::string path_;
  std::vector<PresetEntry> entries_;
};

/// The option names each process reads from a preset, by section ("actor", "replay", "learner",
/// "evaluator"): what `PROGRAM --list-options` prints (common/options.h).
using OptionNames = std::map<std::string, std::set<std::string>>;

/// Top-level keys that are the launcher's own ("actors": the actor processes it starts).
inline const std::set<std::string>& LauncherKeys() {
  static const std::set<std::string> keys = {"actors"};
  return keys;
}

/// Asks each process of `sections` for its option names (`BIN_DIR/SECTION --list-options`).
/// Throws LaunchError when a program is missing or fails.
OptionNames ListOptionNames(const std::string& bin_dir, const std::vector<std::string>& sections);

/// Checks every key of `preset`: a section must be one of `known`'s, a key in a section must be
/// an option of that section's process, and a top-level key an option of at least one process or
/// one of LauncherKeys(). Throws LaunchError naming the file, the section and the key (and the
/// nearest known name, when one is close).
void CheckPreset(const Preset& preset, const OptionNames& known);

}  // namespace rl::launch
