#include "tools/metrics_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "common/messages.h"
#include "evaluator/json_line.h"
#include "evaluator/training_curves.h"

namespace rl::tools {
namespace {

// Builds {"t": ..., "role": "...", "key": value, ...} one field at a time (json_line.h).
class Line {
 public:
  Line(double t, const std::string& role) {
    fields_["t"] = std::round(t * 1000) / 1000;  // milliseconds are plenty
    fields_["role"] = role;
  }
  Line& Add(const char* key, int64_t value) {
    fields_[key] = value;
    return *this;
  }
  // Ten significant digits are plenty, and keep the lines short.
  Line& Add(const char* key, double value) {
    if (std::isfinite(value)) {
      char digits[32];
      std::snprintf(digits, sizeof(digits), "%.10g", value);
      value = std::strtod(digits, nullptr);
    }
    fields_[key] = value;
    return *this;
  }
  std::string Done() const { return JsonLine(fields_) + "\n"; }

 private:
  nlohmann::ordered_json fields_;
};

// The fields every role has: its drops, and the age of the message in tenths of a second.
template <class Stats>
Line& AddDrops(Line& line, const Stats& s, double age) {
  return line.Add("lost", static_cast<int64_t>(s.lost))
      .Add("dropped", static_cast<int64_t>(Dropped(s)))
      .Add("replayed", static_cast<int64_t>(s.dropped_replayed))
      .Add("unauthenticated", static_cast<int64_t>(s.dropped_unauthenticated))
      .Add("age", std::round(age * 10) / 10);
}

}  // namespace

std::string MetricsLine(double t, const rlmsg::stats_actor_t& s, double age) {
  Line line(t, s.header.sender);
  line.Add("env_steps", static_cast<int64_t>(s.env_steps))
      .Add("episodes", static_cast<int64_t>(s.episodes))
      .Add("mean_return", s.mean_return)
      .Add("exploration", s.epsilon)
      .Add("steps_per_second", s.steps_per_second)
      .Add("weights_version", static_cast<int64_t>(s.weights_version))
      .Add("paused", static_cast<int64_t>(s.paused));
  return AddDrops(line, s, age).Done();
}

std::string MetricsLine(double t, const rlmsg::stats_replay_t& s, double age) {
  Line line(t, s.header.sender);
  line.Add("size", static_cast<int64_t>(s.size))
      .Add("capacity", static_cast<int64_t>(s.capacity))
      .Add("inserts", static_cast<int64_t>(s.total_inserts))
      .Add("samples", static_cast<int64_t>(s.total_samples))
      .Add("inserts_per_second", s.inserts_per_second)
      .Add("samples_per_second", s.samples_per_second)
      .Add("samples_per_insert", s.samples_per_insert)
      .Add("insert_allowed", static_cast<int64_t>(s.insert_allowed))
      .Add("memory_bytes", static_cast<int64_t>(s.memory_bytes));
  return AddDrops(line, s, age).Done();
}

std::string MetricsLine(double t, const rlmsg::stats_learner_t& s, double age) {
  Line line(t, s.header.sender);
  line.Add("updates", static_cast<int64_t>(s.updates))
      .Add("updates_per_second", s.updates_per_second)
      .Add("loss", s.loss)
      .Add("mean_q", s.mean_q)
      .Add("env_steps", static_cast<int64_t>(s.env_steps))
      .Add("weights_version", static_cast<int64_t>(s.weights_version));
  return AddDrops(line, s, age).Done();
}

std::string MetricsLine(double t, const rlmsg::stats_evaluator_t& s, double age) {
  Line line(t, s.header.sender);
  line.Add("checkpoints_scored", static_cast<int64_t>(s.checkpoints_scored))
      .Add("last_mean", s.last_mean)
      .Add("best_mean", s.best_mean)
      .Add("busy", static_cast<int64_t>(s.busy));
  return AddDrops(line, s, age).Done();
}

namespace {

// The t of the last line of the file at `path` that is a JSON object with a number t, read from
// its last 64 KB (many rows); 0 when there is none.
double LastT(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return 0;
  const std::streamoff size = in.tellg();
  const std::streamoff from = std::max<std::streamoff>(0, size - (64 << 10));
  in.seekg(from);
  std::string tail(static_cast<size_t>(size - from), '\0');
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  tail.resize(static_cast<size_t>(in.gcount()));
  size_t end = tail.size();
  while (end > 0) {
    const size_t begin = tail.rfind('\n', end - 1);
    const size_t first = begin == std::string::npos ? 0 : begin + 1;
    if (const auto object = ParseJsonLine(std::string_view(tail).substr(first, end - first))) {
      if (const auto t = JsonNumberAt(*object, "t")) return *t;
    }
    if (begin == std::string::npos) break;
    end = begin;
  }
  return 0;
}

}  // namespace

int64_t ActorEpisodes(const std::string& path) { return evaluator::LoadActorEpisodes(path).total; }

MetricsLog::MetricsLog(const std::string& path, double dense_seconds, double dense_period,
                       double sparse_period)
    : path_(path),
      dense_seconds_(dense_seconds),
      dense_period_(dense_period),
      sparse_period_(sparse_period) {
  if (!(dense_period > 0) || !(sparse_period > 0) || !(dense_seconds >= 0)) {
    throw std::invalid_argument("metrics: periods must be > 0 and dense_seconds >= 0");
  }
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error("cannot open metrics file " + path + ": " + std::strerror(errno));
  }
  last_t_ = LastT(path);
}

MetricsLog::~MetricsLog() {
  if (fd_ >= 0) ::close(fd_);
}

bool MetricsLog::Due(double t) const { return t >= next_; }

void MetricsLog::AppendRow(double t, const std::string& lines) {
  // One write: a kill between system calls leaves whole lines.
  const ssize_t n = ::write(fd_, lines.data(), lines.size());
  if (n != static_cast<ssize_t>(lines.size())) {
    throw std::runtime_error("cannot append to metrics file " + path_ + ": " +
                             (n < 0 ? std::strerror(errno) : "short write"));
  }
  ++rows_;
  const double period = t < dense_seconds_ ? dense_period_ : sparse_period_;
  next_ = (std::floor(t / period) + 1) * period;
}

}  // namespace rl::tools
