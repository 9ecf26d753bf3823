#include "launch/slurm_placement.h"

#include <unistd.h>

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "launch/launch_options.h"
#include "launch/proc.h"

namespace rl::launch {
namespace {

// The path of `program` on the PATH, or empty.
std::string FindOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    std::string candidate = dir + "/" + program;
    if (!dir.empty() && access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

std::string Env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? v : "";
}

std::vector<std::string> Words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The value of KEY=VALUE among the words of `text` ("NodeAddr=198.18.1.11 ..."), or empty.
std::string Field(const std::string& text, const std::string& key) {
  for (const std::string& w : Words(text)) {
    if (w.compare(0, key.size() + 1, key + "=") == 0) return w.substr(key.size() + 1);
  }
  return "";
}

// A whole number >= 1, the whole of `text`; 0 otherwise.
int Count(const std::string& text) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  return ec == std::errc() && end == text.data() + text.size() && v >= 1 ? v : 0;
}

std::string Plural(int n, const char* what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

}  // namespace

std::vector<int> ParseCpusPerNode(const std::string& text, size_t nodes) {
  std::vector<int> cpus;
  std::istringstream in(text);
  for (std::string run; std::getline(in, run, ',');) {
    // N or N(xK)
    const size_t paren = run.find("(x");
    const int n = Count(run.substr(0, paren));
    int repeat = 1;
    if (paren != std::string::npos) {
      repeat = run.back() == ')' ? Count(run.substr(paren + 2, run.size() - paren - 3)) : 0;
    }
    if (n == 0 || repeat == 0 || cpus.size() + static_cast<size_t>(repeat) > 100000) {
      throw LaunchError("cannot read SLURM_JOB_CPUS_PER_NODE '" + text + "'");
    }
    cpus.insert(cpus.end(), static_cast<size_t>(repeat), n);
  }
  if (cpus.size() != nodes) {
    throw LaunchError("SLURM_JOB_CPUS_PER_NODE '" + text + "' counts " +
                      Plural(static_cast<int>(cpus.size()), "node") + ", the job has " +
                      Plural(static_cast<int>(nodes), "node"));
  }
  return cpus;
}

std::vector<int> ActorsPerNode(const std::vector<int>& cpus, std::optional<int> per_node) {
  const std::string ask =
      " (ask Slurm for more: sbatch --exclusive, --ntasks-per-node=N or --mincpus=N)";
  std::vector<int> actors;
  int total = 0;
  for (size_t i = 0; i < cpus.size(); ++i) {
    const int others = i == 0 ? kFirstNodeProcesses : 0;
    const int want = per_node ? *per_node + others : others;
    if (cpus[i] < want) {
      throw LaunchError("the job has " + Plural(cpus[i], "core") + " on its " +
                        (i == 0 ? "first node" : "node " + std::to_string(i + 1)) +
                        ", which needs " + std::to_string(want) + " (" +
                        (i == 0 ? std::string("the replay, the learner and the evaluator") : "") +
                        (i == 0 && per_node && *per_node > 0 ? " and " : "") +
                        (per_node && *per_node > 0 ? Plural(*per_node, "actor") : "") + ")" + ask);
    }
    actors.push_back(per_node ? *per_node : cpus[i] - others);
    total += actors.back();
  }
  if (total == 0) {
    throw LaunchError(
        "no actor would run: the job's cores all go to the replay, the learner and the "
        "evaluator" +
        ask);
  }
  return actors;
}

SlurmJob ReadSlurmJob() {
  const std::string scontrol = FindOnPath("scontrol");
  for (const char* program : {"srun", "scontrol", "squeue", "sinfo"}) {
    if (FindOnPath(program).empty()) {
      throw LaunchError(std::string("--slurm needs Slurm's ") + program +
                        " on the PATH (it is not: is this a Slurm node? Debian's slurm-client)");
    }
  }
  SlurmJob job;
  job.job_id = Env("SLURM_JOB_ID");
  const std::string nodelist = Env("SLURM_JOB_NODELIST");
  if (job.job_id.empty() || nodelist.empty()) {
    throw LaunchError(
        "--slurm runs inside a Slurm job (no SLURM_JOB_ID here): submit it with "
        "sbatch scripts/slurm.sbatch PRESET");
  }
  try {
    job.nodes = Words(RunAndCapture({scontrol, "show", "hostnames", nodelist}));
  } catch (const std::exception& e) {
    throw LaunchError(std::string("cannot list the job's nodes: ") + e.what());
  }
  job.cpus = ParseCpusPerNode(Env("SLURM_JOB_CPUS_PER_NODE"), job.nodes.size());
  // The launcher's own node first: the replay, learner and evaluator go there, beside it.
  const std::string self = Env("SLURMD_NODENAME");
  for (size_t i = 1; i < job.nodes.size(); ++i) {
    if (job.nodes[i] == self) {
      std::swap(job.nodes[0], job.nodes[i]);
      std::swap(job.cpus[0], job.cpus[i]);
    }
  }
  try {
    job.first_address =
        Field(RunAndCapture({scontrol, "show", "node", "-o", job.nodes.at(0)}), "NodeAddr");
  } catch (const std::exception& e) {
    throw LaunchError("cannot read node " + job.nodes.at(0) + "'s address: " + e.what());
  }
  if (job.first_address.empty()) {
    throw LaunchError("scontrol shows no NodeAddr for node " + job.nodes[0]);
  }
  return job;
}

SlurmPlacement::SlurmPlacement(SlurmJob job, std::vector<int> actors)
    : job_(std::move(job)), actors_(std::move(actors)) {
  for (int n : actors_) total_ += n;
}

std::string SlurmPlacement::Describe() const {
  std::string s = "Slurm job " + job_.job_id + ": ";
  for (size_t i = 0; i < job_.nodes.size(); ++i) {
    s += (i == 0 ? "" : ", ") + job_.nodes[i] + " (" +
         (i == 0 ? "replay, learner, evaluator, " : "") + Plural(actors_[i], "actor") + ")";
  }
  return s;
}

const std::string& SlurmPlacement::NodeOf(int actor_id) const {
  int first = 0;
  for (size_t i = 0; i < actors_.size(); ++i) {
    if (actor_id < first + actors_[i]) return job_.nodes[i];
    first += actors_[i];
  }
  return job_.nodes.back();
}

bool SlurmPlacement::IsStep(const PlannedProcess& p) {
  return p.kind == "replay" || p.kind == "learner" || p.kind == "evaluator" || p.kind == "actor";
}

std::vector<std::string> SlurmPlacement::Command(const PlannedProcess& process) const {
  if (!IsStep(process)) return process.argv;
  const std::string& node = process.kind == "actor" ? NodeOf(process.actor_id) : job_.nodes[0];
  // One task on the node, beside the job's other steps (--overlap), on any of its cores.
  std::vector<std::string> c = {"srun",
                                "--nodes=1",
                                "--ntasks=1",
                                "--nodelist=" + node,
                                "--overlap",
                                "--cpu-bind=none",
                                "--job-name=" + process.role};
  c.insert(c.end(), process.argv.begin(), process.argv.end());
  return c;
}

int SlurmPlacement::StopSignal(const PlannedProcess& process) const {
  return IsStep(process) ? SIGUSR2 : SIGTERM;
}

std::string SlurmPlacement::Ending() const {
  std::string state;
  try {
    const std::vector<std::string> words =
        Words(RunAndCapture({FindOnPath("squeue"), "-h", "-j", job_.job_id, "-o", "%T"}));
    if (!words.empty()) state = words[0];
  } catch (const std::exception&) {
    return "";  // Slurm did not answer: taken for a crash, restarted as usual
  }
  if (state.empty() || state == "RUNNING") return "";
  for (char& c : state) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return "the Slurm job " + job_.job_id + " is " + state + " (cancelled or requeued)";
}

std::string SlurmPlacement::Lost(const PlannedProcess& process) const {
  if (process.kind != "actor") return "";
  const std::string& node = NodeOf(process.actor_id);
  if (node == job_.nodes[0]) return "";
  if (lost_.count(node) == 0) {
    std::string state;
    bool in_job = true;
    try {
      state = Words(RunAndCapture({FindOnPath("sinfo"), "-h", "-N", "-n", node, "-o", "%t"})).at(0);
      const std::string list =
          RunAndCapture({FindOnPath("squeue"), "-h", "-j", job_.job_id, "-o", "%N"});
      const std::vector<std::string> names = Words(list);
      if (!names.empty()) {
        in_job = false;
        for (const std::string& n :
             Words(RunAndCapture({FindOnPath("scontrol"), "show", "hostnames", names[0]}))) {
          in_job |= n == node;
        }
      }
    } catch (const std::exception&) {
      return "";  // Slurm did not answer: taken for a crash, restarted as usual
    }
    const bool bad = state.find('*') != std::string::npos || state.rfind("down", 0) == 0 ||
                     state.rfind("drain", 0) == 0 || state.rfind("fail", 0) == 0;
    if (in_job && !bad) return "";
    lost_.insert(node);
    return "its node " + node + " is lost (" + (in_job ? "" : "left the job, ") + "state " + state +
           ")";
  }
  return "its node " + node + " is lost";
}

}  // namespace rl::launch
