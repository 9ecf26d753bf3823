#include "envs/pixel_spec.h"

#include <map>
#include <sstream>
#include <stdexcept>

namespace rl::envs {
namespace {

constexpr char kPixels[] = "+pixels(";

// The integer value of one key; throws unless the whole text is an integer.
int ParseInt(const std::string& id, const std::string& key, const std::string& text) {
  try {
    size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("env '" + id + "': " + key + " must be an integer, got '" + text +
                              "'");
}

}  // namespace

EnvIdParts ParseEnvId(const std::string& id) {
  EnvIdParts parts;
  const size_t at = id.find(kPixels);
  if (at == std::string::npos) {
    parts.base = id;
    return parts;
  }
  parts.base = id.substr(0, at);
  parts.pixels = true;
  const size_t open = at + sizeof(kPixels) - 1;
  const size_t close = id.find(')', open);
  if (close == std::string::npos || close + 1 != id.size()) {
    throw std::invalid_argument("env '" + id +
                                "': expected <id>+pixels(key=value,...) ending in ')'");
  }
  ImagePipelineConfig& c = parts.image;
  const std::map<std::string, int*> ints = {
      {"width", &c.width},
      {"height", &c.height},
      {"stack", &c.stack},
      {"skip", &c.frame_skip},
      {"crop-top", &c.crop_top},
      {"crop-bottom", &c.crop_bottom},
      {"crop-left", &c.crop_left},
      {"crop-right", &c.crop_right},
      {"render-width", &c.render_width},
      {"render-height", &c.render_height},
      {"noop-start", &c.noop_start},
      {"time-limit", &c.time_limit},
      {"off-track-grace", &parts.off_track_grace},
  };
  std::stringstream list(id.substr(open, close - open));
  std::string item;
  while (std::getline(list, item, ',')) {
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    if (eq == std::string::npos) {
      throw std::invalid_argument("env '" + id + "': expected key=value, got '" + item + "'");
    }
    const std::string value = item.substr(eq + 1);
    if (key == "max-pool" || key == "off-track" || key == "lap-ends" || key == "pedals") {
      const int v = ParseInt(id, key, value);
      if (v != 0 && v != 1) throw std::invalid_argument("env '" + id + "': " + key + " is 0 or 1");
      (key == "max-pool"    ? c.max_pool
       : key == "off-track" ? parts.off_track
       : key == "pedals"    ? parts.pedals
                            : parts.lap_ends) = v == 1;
    } else if (auto it = ints.find(key); it != ints.end()) {
      *it->second = ParseInt(id, key, value);
    } else {
      throw std::invalid_argument(
          "env '" + id + "': unknown pixels key '" + key +
          "' (known: width, height, stack, skip, max-pool, crop-top, crop-bottom, crop-left, "
          "crop-right, render-width, render-height, noop-start, off-track, off-track-grace, "
          "time-limit, lap-ends, pedals)");
    }
  }
  try {
    c.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("env '" + id + "': " + e.what());
  }
  if (parts.off_track_grace < 0 || (parts.off_track_grace > 0 && !parts.off_track)) {
    throw std::invalid_argument("env '" + id +
                                "': off-track-grace is a count of frames >= 0, with off-track=1");
  }
  if ((parts.off_track || !parts.lap_ends) && !parts.base.starts_with("CarRacing")) {
    throw std::invalid_argument("env '" + id +
                                "': " + (parts.off_track ? "off-track" : "lap-ends") +
                                " applies to CarRacing only");
  }
  if (parts.pedals && parts.base != "CarRacing-v3") {
    throw std::invalid_argument("env '" + id +
                                "': pedals applies to CarRacing-v3 only (continuous actions)");
  }
  return parts;
}

}  // namespace rl::envs
