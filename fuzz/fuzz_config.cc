// Fuzz target: the INI presets (configs/*.ini) as every process reads them: rl::ParseOptions()
// with --config naming the input (common/options.h: top-level keys, the process's own section,
// unknown keys of that section refused, typed values), for the actor, learner, replay and
// evaluator roles, then the env ids found (env, eval-env) through the spec lookup
// (envs/specs.h). The option tables below mirror the processes' own (their main.cc) in names
// and value types. Contract checked: a bad preset is refused with an exception, nothing worse.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/options.h"
#include "envs/specs.h"
#include "fuzz/fuzz_support.h"

namespace {

namespace po = rl::po;

enum class Type { kString, kInt, kInt64, kUint64, kFloat, kDouble, kBool, kSwitch };
struct Key {
  const char* name;
  Type type;
};

void AddKey(po::options_description* desc, const Key& key) {
  auto add = desc->add_options();
  switch (key.type) {
    case Type::kString:
      add(key.name, po::value<std::string>());
      break;
    case Type::kInt:
      add(key.name, po::value<int>());
      break;
    case Type::kInt64:
      add(key.name, po::value<int64_t>());
      break;
    case Type::kUint64:
      add(key.name, po::value<uint64_t>());
      break;
    case Type::kFloat:
      add(key.name, po::value<float>());
      break;
    case Type::kDouble:
      add(key.name, po::value<double>());
      break;
    case Type::kBool:
      add(key.name, po::value<bool>());
      break;
    case Type::kSwitch:
      add(key.name, po::bool_switch());
      break;
  }
}

struct Role {
  std::string name;
  po::options_description desc;
};

using T = Type;
const Key kActor[] = {
    {"env", T::kString},
    {"actor-id", T::kInt},
    {"num-actors", T::kInt},
    {"envs-per-actor", T::kInt},
    {"seed", T::kUint64},
    {"batch-size", T::kInt},
    {"n-step", T::kInt},
    {"gamma", T::kFloat},
    {"exploration", T::kString},
    {"apex-base", T::kDouble},
    {"apex-alpha", T::kDouble},
    {"epsilon-start", T::kDouble},
    {"epsilon-end", T::kDouble},
    {"epsilon-anneal-steps", T::kInt64},
    {"sigma", T::kFloat},
    {"sigma-end", T::kFloat},
    {"sigma-anneal-steps", T::kInt64},
    {"noise-spread", T::kFloat},
    {"start-steps", T::kInt64},
    {"stats-hz", T::kDouble},
    {"clip-rewards", T::kBool},
    {"max-steps", T::kInt64},
};
const Key kLearner[] = {
    {"env", T::kString},
    {"out", T::kString},
    {"algorithm", T::kString},
    {"network", T::kString},
    {"hidden", T::kString},
    {"tau", T::kFloat},
    {"adam-eps", T::kFloat},
    {"max-grad-norm", T::kFloat},
    {"seed", T::kUint64},
    {"batch-size", T::kInt},
    {"prioritized", T::kBool},
    {"augment-shift", T::kInt},
    {"dueling", T::kBool},
    {"optimizer", T::kString},
    {"learning-rate", T::kFloat},
    {"rmsprop-alpha", T::kFloat},
    {"rmsprop-eps", T::kFloat},
    {"rmsprop-centered", T::kBool},
    {"loss", T::kString},
    {"double-dqn", T::kBool},
    {"target-update-period", T::kInt},
    {"actor-learning-rate", T::kFloat},
    {"critic-learning-rate", T::kFloat},
    {"policy-delay", T::kInt},
    {"target-noise", T::kFloat},
    {"target-noise-clip", T::kFloat},
    {"requests-in-flight", T::kInt},
    {"request-timeout", T::kDouble},
    {"weights-every", T::kInt64},
    {"checkpoint-every", T::kInt64},
    {"keep-checkpoints", T::kInt},
    {"threads", T::kInt},
    {"resume", T::kSwitch},
    {"max-updates", T::kInt64},
    {"stats-hz", T::kDouble},
};
const Key kReplay[] = {
    {"env", T::kString},
    {"capacity", T::kInt64},
    {"obs-size", T::kInt},
    {"seed", T::kUint64},
    {"prioritized", T::kBool},
    {"alpha", T::kDouble},
    {"beta", T::kDouble},
    {"beta-anneal-samples", T::kInt64},
    {"frame-capacity", T::kInt64},
    {"min-size", T::kInt64},
    {"samples-per-insert", T::kDouble},
    {"error-buffer", T::kDouble},
    {"flow-hz", T::kDouble},
    {"stats-hz", T::kDouble},
};
const Key kEvaluator[] = {
    {"checkpoint", T::kString}, {"env", T::kString},
    {"eval-env", T::kString},   {"episodes", T::kInt},
    {"epsilon", T::kDouble},    {"gamma", T::kDouble},
    {"seed-base", T::kUint64},  {"out", T::kString},
    {"goal", T::kDouble},       {"stop-at-goal", T::kSwitch},
    {"videos", T::kInt},        {"video-width", T::kInt},
    {"video-height", T::kInt},  {"video-fps", T::kInt},
    {"frames", T::kString},     {"tsne", T::kInt},
    {"tsne-map", T::kString},   {"run-config", T::kString},
};

template <size_t N>
Role MakeRole(const std::string& name, const Key (&keys)[N]) {
  Role role{name, po::options_description("Options")};
  static rl::CommonOptions common;
  rl::AddCommonOptions(&role.desc, &common);
  for (const Key& key : keys) AddKey(&role.desc, key);
  return role;
}

const std::vector<Role>& Roles() {
  static const std::vector<Role> roles = [] {
    std::vector<Role> r;
    r.push_back(MakeRole("actor", kActor));
    r.push_back(MakeRole("learner", kLearner));
    r.push_back(MakeRole("replay", kReplay));
    r.push_back(MakeRole("evaluator", kEvaluator));
    return r;
  }();
  return roles;
}

void LookupEnv(const po::variables_map& vm, const char* key) {
  if (!vm.count(key)) return;
  try {
    rl::envs::LookupSpec(vm[key].as<std::string>());
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static rl::fuzz::MemFile file("config");
  std::string path = file.Write(std::string_view(reinterpret_cast<const char*>(data), size));
  std::string program = "fuzz_config", flag = "--config";
  char* argv[] = {program.data(), flag.data(), path.data(), nullptr};
  for (const Role& role : Roles()) {
    po::variables_map vm;
    try {
      if (!rl::ParseOptions(3, argv, role.name, "usage", role.desc, &vm)) continue;
    } catch (const std::exception&) {
      continue;
    }
    LookupEnv(vm, "env");
    LookupEnv(vm, "eval-env");
  }
  return 0;
}
