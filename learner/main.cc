// The learner process: see learner/learner.h and learner/README.md.
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/options.h"
#include "common/shutdown.h"
#include "learner/learner.h"
#include "nn/precision.h"

namespace {

std::vector<int> ParseWidths(const std::string& text) {
  std::vector<int> widths;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      widths.push_back(std::stoi(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::invalid_argument("hidden: expected comma-separated widths like 120,84, got '" +
                                  text + "'");
    }
  }
  return widths;
}

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  rl::learner::LearnerConfig c;
  // Settings every algorithm has but with defaults of its own are left without one here and set
  // on the chosen algorithm's config only when given (learner/algorithms.h).
  std::string network, hidden;
  float tau = 0, adam_eps = 0, max_grad_norm = 0;
  uint64_t seed = 0;
  std::string algorithms;  // the --algorithm help: a sentence per algorithm
  rl::learner::ForEachAlgorithm(c.algorithms, [&](const auto& config) {
    algorithms +=
        (algorithms.empty() ? "" : ". ") + std::string(config.kName) + ": " + config.kSummary;
  });
  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()                                                                //
      ("env", rl::po::value(&c.env_id)->default_value(c.env_id), "environment id")  //
      ("out", rl::po::value(&c.out_dir)->default_value(c.out_dir),
       "run folder; checkpoints go to <out>/checkpoints")  //
      ("algorithm", rl::po::value(&c.algorithm)->default_value(c.algorithm),
       algorithms.c_str())  //
      ("network", rl::po::value(&network),
       "dqn: the Q network, mlp (default), nature (Mnih et al. 2015, 4x84x84 frames), grasp "
       "(stacks of 40x40 frames), grasp48 (stacks of 48x48 frames) or an architecture string; "
       "td3: mlp (default), car (the TD3 CarRacing article's CNNs, 4x84x84 frames) or drq (the "
       "article's encoder shared by actor and critics, trained by the critics, with DrQ-v2 heads "
       "of width hidden[0])")  //
      ("hidden", rl::po::value(&hidden),
       "hidden layer widths of the MLPs (dqn default 120,84; td3 default 256,256; td3 drq: the "
       "heads' width is the first)")  //
      ("tau", rl::po::value(&tau),
       "target update weight of the online network (dqn default 1: hard copy every "
       "target-update-period; td3 default 0.005: Polyak, every policy-delay updates)")  //
      ("adam-eps", rl::po::value(&adam_eps), "Adam epsilon (default 1e-8)")             //
      ("max-grad-norm", rl::po::value(&max_grad_norm),
       "gradient norm clip, 0: none (dqn default 10, td3 default 0)")          //
      ("seed", rl::po::value(&seed)->default_value(0), "initialisation seed")  //
      ("batch-size", rl::po::value(&c.batch_size)->default_value(c.batch_size),
       "transitions per update")  //
      ("prioritized", rl::po::value(&c.prioritized)->default_value(c.prioritized),
       "send |TD errors| to the replay as priorities after every update (1/0)")  //
      ("augment-shift", rl::po::value(&c.augment_shift)->default_value(c.augment_shift),
       "pixel envs: shift every sampled observation by a random offset of up to this many "
       "pixels, edges repeated (DrQ, Kostrikov et al. 2020); 0: none")  //
      ("requests-in-flight",
       rl::po::value(&c.requests_in_flight)->default_value(c.requests_in_flight),
       "sample requests outstanding at once")  //
      ("request-timeout", rl::po::value(&c.request_timeout)->default_value(c.request_timeout),
       "seconds before a sample request is sent again")  //
      ("weights-every", rl::po::value(&c.weights_every)->default_value(c.weights_every),
       "updates between weight broadcasts")  //
      ("checkpoint-every", rl::po::value(&c.checkpoint_every)->default_value(c.checkpoint_every),
       "updates between checkpoints")  //
      ("keep-checkpoints", rl::po::value(&c.keep_checkpoints)->default_value(c.keep_checkpoints),
       "newest checkpoint files kept on disk, those earlier lives of the learner left in the "
       "folder included (0: all)")  //
      ("policy-average", rl::po::value(&c.policy_average)->default_value(c.policy_average),
       "checkpoints, and so the evaluator's scores, hold an exponential moving average of the "
       "policy's parameters over about this many updates (the actors still explore with the "
       "current ones); 0: the current parameters")  //
      ("learning-rate-decay-updates",
       rl::po::value(&c.learning_rate_decay_updates)->default_value(c.learning_rate_decay_updates),
       "the learning rates fall linearly over this many updates to learning-rate-end times "
       "their start, then stay there; a resumed learner continues the schedule (0: constant)")  //
      ("learning-rate-end", rl::po::value(&c.learning_rate_end)->default_value(c.learning_rate_end),
       "the fraction of the learning rates left at the end of that decay, in [0, 1]")  //
      ("precision", rl::po::value(&c.precision)->default_value(c.precision),
       "the networks' matrix products: fp32, or bf16 (inputs rounded to bfloat16, sums in fp32; "
       "weights, optimizer, activations and losses stay fp32), or auto (bf16 where the CPU has "
       "AVX512_BF16, fp32 elsewhere; a resume keeps the saved state's). bf16 is fast on CPUs "
       "with AVX512_BF16 and emulated, slower than fp32, elsewhere; the kernels follow the CPU, "
       "or RL_KERNELS (avx512_bf16, avx512, avx2)")  //
      ("threads", rl::po::value(&c.threads)->default_value(c.threads),
       "compute threads for the network (convolutions and large products are split; 1 leaves "
       "the other cores to the actors)")  //
      ("resume", rl::po::bool_switch(&c.resume),
       "continue from <out>/checkpoints/learner-state.bin when it exists (written with every "
       "checkpoint): networks, targets, optimizer states, update count, env steps, generators; "
       "a state of another algorithm, network or env is refused")  //
      ("max-updates", rl::po::value(&c.max_updates)->default_value(c.max_updates),
       "stop after this many updates (0: until stopped)")  //
      ("stats-hz", rl::po::value(&c.stats_hz)->default_value(c.stats_hz),
       "stats messages per second");
  // Each algorithm's own options, in a section of the help of their own.
  std::map<std::string, std::vector<std::string>> own_options;
  rl::learner::ForEachAlgorithm(c.algorithms, [&](auto& config) {
    rl::po::options_description own(std::string("Options of ") + config.kName);
    config.AddOptions(&own);
    std::vector<std::string>& names = own_options[config.kName];  // also for one with none
    for (const auto& option : own.options()) names.push_back(option->long_name());
    desc.add(own);
  });
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "learner",
                        "Usage: learner [options]\n"
                        "Trains a DQN or a TD3 on batches sampled from the replay daemon, "
                        "broadcasts its policy network's weights and writes checkpoints.",
                        desc, &vm)) {
    return 0;
  }
  rl::learner::CheckAlgorithmName(c.algorithm);
  for (const auto& [name, options] : own_options) {
    if (name != c.algorithm) {
      rl::RefuseGiven(vm, options,
                      "algorithm is " + c.algorithm + ", and it is an option of " + name);
    }
  }
  rl::learner::ForEachAlgorithm(c.algorithms, [&](auto& config) {
    if (c.algorithm != config.kName) return;
    if (vm.count("network")) config.network = network;
    if (vm.count("hidden")) config.hidden = ParseWidths(hidden);
    if (vm.count("tau")) config.tau = tau;
    if (vm.count("adam-eps")) config.adam_eps = adam_eps;
    if (vm.count("max-grad-norm")) config.max_grad_norm = max_grad_norm;
    config.seed = seed;
  });
  c.seed = seed;
  // The kernels the networks will run on (throws, naming the reason, when RL_KERNELS asks for a
  // path this CPU cannot run).
  const std::string kernel_path = rl::nn::KernelPath();
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("learner"));
  rl::learner::Learner learner(c, &bus);
  const std::string& precision = learner.precision();
  const std::string& encoder_precision = c.Get<rl::learner::Td3Config>().encoder_precision;
  std::string kernels = "precision " + precision;
  if (c.precision == "auto") {
    kernels += learner.resumed()      ? " (auto: the saved state's)"
               : rl::nn::NativeBf16() ? " (auto: the CPU has AVX512_BF16)"
                                      : " (auto: no AVX512_BF16)";
  }
  if (c.algorithm == rl::learner::Td3Config::kName && !encoder_precision.empty()) {
    kernels += " (the shared encoder's: " + encoder_precision + ")";
  }
  kernels += ", " + kernel_path + " kernels";
  if ((precision == "bf16" || encoder_precision == "bf16") && !rl::nn::NativeBf16()) {
    kernels += ", bf16 emulated: no AVX512_BF16";
    std::fprintf(stderr,
                 "learner: warning: this CPU (or RL_KERNELS) gives no AVX512_BF16: bf16 products "
                 "are emulated (the same rounding, slower than fp32)\n");
  }
  std::string shifts;
  if (const int k = c.augment_shift; k > 0) {
    shifts = ", random shifts of up to " + std::to_string(k) + " pixels";
  }
  std::string resumed;
  if (learner.resumed()) {
    resumed = ", resumed at update " + std::to_string(learner.updates());
  } else if (c.resume) {
    resumed = ", nothing to resume: starting afresh";
  }
  const std::string average =
      c.policy_average > 0
          ? ", checkpoints average the policy over " + std::to_string(c.policy_average) + " updates"
          : "";
  std::string decay;
  if (c.learning_rate_decay_updates > 0) {
    char text[160];
    std::snprintf(text, sizeof text, ", learning rates falling to %g of their start by update %lld",
                  c.learning_rate_end, static_cast<long long>(c.learning_rate_decay_updates));
    decay = text;
  }
  std::printf("learner: ready (%s)%s, %s%s%s%s\n", learner.algorithm().Describe().c_str(),
              shifts.c_str(), kernels.c_str(), average.c_str(), decay.c_str(), resumed.c_str());
  std::fflush(stdout);
  learner.Run();
  std::printf("learner: stopped after %lld updates\n", static_cast<long long>(learner.updates()));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("learner", Main, argc, argv); }
