// The evaluator: scores the checkpoints of a run and writes its report (service mode), or scores
// one checkpoint file (standalone mode). See README.md.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/clock.h"
#include "common/lcm_bus.h"
#include "common/options.h"
#include "common/shutdown.h"
#include "envs/specs.h"
#include "evaluator/checkpoint_file.h"
#include "evaluator/evaluator_service.h"
#include "evaluator/frame_grid.h"
#include "evaluator/report.h"
#include "evaluator/scheduling.h"
#include "evaluator/tsne_map.h"

namespace {

constexpr char kUsage[] =
    "Usage:\n"
    "  evaluator --out DIR [options]\n"
    "      Service mode: scores every checkpoint the learner announces on RL_CHECKPOINT (the\n"
    "      newest first; superseded ones later, see --backlog), appends DIR/eval.jsonl,\n"
    "      rewrites DIR/report/index.html and its learning curves, publishes RL_EVAL and\n"
    "      RL_STATS_EVALUATOR. Prints 'evaluator: ready' once subscribed. Stops on SIGINT or\n"
    "      SIGTERM, or with --stop-at-goal once a checkpoint reaches the goal, and then prints\n"
    "      'evaluator: goal reached' or 'evaluator: goal not reached (best X)'; exit status 0.\n"
    "  evaluator --checkpoint FILE [--env ID] [--episodes N] [--epsilon E] [--noise S]\n"
    "            [--ensemble K [--ensemble-by weights [--save-average OUT]]]\n"
    "            [--seed-base S] [--gamma G] [--frames PNG]\n"
    "            [--tsne-map PNG [--tsne N]]\n"
    "      Standalone mode: scores one checkpoint file and prints one JSON object (checkpoint,\n"
    "      update, env_steps, wall_seconds, mean, std, min, max, episodes, eval_seconds,\n"
    "      value_steps, value_estimate, value_return, value_correlation: the network's value\n"
    "      estimates of the actions taken against the discounted returns that followed, and\n"
    "      returns and steps: each episode's return and length).\n"
    "      --noise (continuous actions) scores the policy with the actors' Gaussian noise at\n"
    "      that constant sigma (of the half-range) instead of its deterministic action, to\n"
    "      compare the two; the standard metric is without noise.\n"
    "      --ensemble K (continuous actions) scores the mean action of FILE and the K - 1\n"
    "      checkpoints before it in its folder (the learner's ckpt-<update>.bin files); only\n"
    "      on the command line: a --config file's ensemble is the service's. With\n"
    "      --ensemble-by weights (any env) it scores instead the one network whose weights are\n"
    "      the mean of those checkpoints', and --save-average writes that network to OUT, a\n"
    "      checkpoint file like the learner's.\n"
    "      --frames also writes the grid of camera frames the report shows (pixel envs),\n"
    "      --tsne-map the t-SNE map of its last hidden layer (pixel envs; N states, 2000 by\n"
    "      default).\n"
    "      A refused file prints 'evaluator: error: <reason>' and exits with status 2.\n"
    "\n"
    "Episode i of an evaluation is reset with seed seed-base + i; the default seed base is far\n"
    "above the seeds actors train with, so evaluation never replays a training seed.\n"
    "\n"
    "--tsne N (pixel envs): the report gets a t-SNE map of the network's last hidden layer, as in\n"
    "Mnih et al. 2015, Figure 4 (report/tsne.png): N states of greedy episodes of a new best\n"
    "checkpoint placed by a 2-D t-SNE embedding of the activations, coloured by value (DQN:\n"
    "max_a Q(s, a); TD3: the discounted return that followed), with some of their frames. A map\n"
    "costs N greedy steps and an O(N^2) embedding (under 1 s of CPU for 2000 states). Maps are\n"
    "made after a checkpoint's result, within a fifth of the evaluator's time, so not every new\n"
    "best gets one at once; a checkpoint that reaches the goal gets its map before its result\n"
    "when that is expected to take at most 15 s.";

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Standalone mode's --tsne-map: the map of one checkpoint, with progress lines on stderr.
void WriteTsneMapOfCheckpoint(const std::string& checkpoint, rl::evaluator::EvaluatorConfig config,
                              const rl::po::variables_map& vm, const std::string& path) {
  if (vm["tsne"].defaulted()) config.tsne = 2000;
  if (config.tsne == 0) throw std::invalid_argument("--tsne-map needs --tsne N above 0");
  config.Validate();
  rl::nn::Sequential net = rl::evaluator::LoadPolicyNetwork(checkpoint, config.env_id);
  const double start = rl::MonoSeconds();
  const rl::evaluator::StateSamples samples = rl::evaluator::CollectStates(
      &net, config.env_id, config.tsne, config.seed_base, config.gamma);
  std::fprintf(stderr, "evaluator: t-SNE map: %d states of %d greedy episodes (%.1f s)\n",
               config.tsne, samples.episodes, rl::MonoSeconds() - start);
  const rl::evaluator::TsneMapResult map = rl::evaluator::WriteTsneMap(
      samples, rl::evaluator::TsneConfig(), path, [](const rl::evaluator::TsneProgress& p) {
        if (p.iteration % 250 == 0) {
          std::fprintf(stderr, "evaluator: t-SNE iteration %d of %d, KL divergence %.3f\n",
                       p.iteration, p.iterations, p.kl_divergence);
        }
      });
  std::fprintf(stderr, "evaluator: t-SNE map written to %s (%d features, %.1f s)\n", path.c_str(),
               map.features, rl::MonoSeconds() - start);
}

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  rl::evaluator::EvaluatorConfig config;
  std::string checkpoint;
  std::string run_config_file;
  std::string eval_env;
  std::string frames_file;
  std::string tsne_file;
  std::string average_file;
  double noise_sigma = 0;
  std::string sched_policy;
  int nice = 0;
  double goal = 0;

  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()  //
      ("checkpoint", rl::po::value(&checkpoint),
       "standalone mode: score this checkpoint file, print one JSON object and exit")  //
      ("env", rl::po::value(&config.env_id)->default_value(config.env_id),
       "environment of the run (the checkpoints are scored on it unless --eval-env is given)")  //
      ("eval-env", rl::po::value(&eval_env),
       "environment the checkpoints are scored on, when it differs from the run's (e.g. "
       "held-out objects and the longer evaluation episodes of KUKA grasping)")  //
      ("episodes", rl::po::value(&config.episodes)->default_value(config.episodes),
       "evaluation episodes per checkpoint")  //
      ("epsilon", rl::po::value(&config.epsilon)->default_value(config.epsilon, "0.05"),
       "discrete actions: exploration rate while scoring (0.05 as in Mnih et al. 2015); "
       "continuous actions are scored without noise")  //
      ("noise", rl::po::value(&noise_sigma),
       "standalone mode, continuous actions: score with the actors' Gaussian noise at this "
       "constant sigma (a fraction of each action's half-range), not the deterministic action")  //
      ("ensemble", rl::po::value(&config.ensemble)->default_value(config.ensemble),
       "score a checkpoint and the K - 1 checkpoints before it in its folder as one, an "
       "ensemble of K networks, by their mean action or their mean weights (--ensemble-by) "
       "(standalone mode: instead of the "
       "checkpoint alone; service mode: after each checkpoint's own score, on the same "
       "episodes, in eval.jsonl and the report beside it); 1: none")  //
      ("ensemble-by", rl::po::value(&config.ensemble_by)->default_value(config.ensemble_by),
       "what an ensemble averages: 'actions' (continuous actions: the members' mean action, "
       "each network run every step) or 'weights' (any env: one network, the mean of the "
       "members' weights; service mode keeps the best as DIR/best-average.bin)")  //
      ("save-average", rl::po::value(&average_file),
       "standalone mode, with --ensemble K --ensemble-by weights: also write the averaged "
       "network to this checkpoint file")  //
      ("ensemble-min-mean", rl::po::value(&config.ensemble_min_mean),
       "service mode: score a checkpoint's ensemble only when its own mean is at least this "
       "(default: every checkpoint's)")  //
      ("gamma", rl::po::value(&config.gamma)->default_value(config.gamma, "0.99"),
       "discount of the returns the network's value estimates are compared with: the actors' "
       "gamma (put gamma at the top of a preset so that both read it)")  //
      ("seed-base", rl::po::value(&config.seed_base)->default_value(config.seed_base),
       "seed of the first evaluation episode (episode i: seed-base + i); keep it away from "
       "training seeds")  //
      ("out", rl::po::value(&config.out_dir),
       "service mode: run folder; writes DIR/eval.jsonl and DIR/report/ (required)")  //
      ("goal", rl::po::value(&goal),
       "mean return that counts as solved (default: the env's reward threshold, 475 for "
       "CartPole-v1)")  //
      ("stop-at-goal", rl::po::bool_switch(&config.stop_at_goal),
       "exit (status 0) right after a checkpoint reaches the goal")  //
      ("videos", rl::po::value(&config.videos)->default_value(config.videos),
       "record a greedy episode of every new best checkpoint as report/best.webm (1/0)")  //
      ("video-width", rl::po::value(&config.video_width)->default_value(config.video_width),
       "video frame width in pixels")  //
      ("video-height", rl::po::value(&config.video_height)->default_value(config.video_height),
       "video frame height in pixels")  //
      ("video-fps", rl::po::value(&config.video_fps)->default_value(config.video_fps),
       "video frames per second")  //
      ("frames", rl::po::value(&frames_file),
       "standalone mode, pixel envs: also write a grid of camera frames and network inputs of "
       "greedy episodes to this PNG file")  //
      ("tsne", rl::po::value(&config.tsne)->default_value(config.tsne),
       "pixel envs: states in the t-SNE map of the last hidden layer of new best checkpoints "
       "(report/tsne.png; 100 to 5000, 2000 is the presets' choice); 0: no map. Standalone mode: "
       "the states of the --tsne-map picture (default 2000)")  //
      ("tsne-map", rl::po::value(&tsne_file),
       "standalone mode, pixel envs: also write the t-SNE map of the checkpoint's last hidden "
       "layer (greedy episodes from the first evaluation seed) to this PNG file")  //
      ("second-env", rl::po::value(&config.second_env),
       "service mode: also score every new best checkpoint on this env (the same observations "
       "and actions), a second metric beside the standard one in eval.jsonl and the report (e.g. "
       "the rules a paper trained and tested with)")  //
      ("second-episodes",
       rl::po::value(&config.second_episodes)->default_value(config.second_episodes),
       "episodes of the second metric")  //
      ("second-name", rl::po::value(&config.second_name),
       "what the report calls the second metric (default: its env id)")  //
      ("second-min-mean", rl::po::value(&config.second_min_mean),
       "score a new best on the second metric only when its standard mean is at least this "
       "(default: every new best)")  //
      ("screen-episodes",
       rl::po::value(&config.screen_episodes)->default_value(config.screen_episodes),
       "service mode: play a checkpoint's first N evaluation episodes first; only one whose mean "
       "is at least the best full evaluation's less --screen-margin gets the full evaluation "
       "(the others are not scored: no eval.jsonl line, no RL_EVAL); 0: no screen")  //
      ("screen-margin", rl::po::value(&config.screen_margin)->default_value(config.screen_margin),
       "service mode: how far below the best full mean a screened checkpoint may be and still "
       "get its full evaluation (return units)")  //
      ("screen-max-rejects",
       rl::po::value(&config.screen_max_rejects)->default_value(config.screen_max_rejects),
       "service mode: after this many checkpoints screened out in a row, the next one is "
       "evaluated in full without a screen")  //
      ("backlog", rl::po::value(&config.backlog)->default_value(config.backlog),
       "service mode: checkpoints superseded by a newer one before their turn wait, up to this "
       "many, and are scored later, newest first, when nothing newer waits (those the learner "
       "has deleted meanwhile are skipped); 0: superseded checkpoints are skipped")  //
      ("sched-policy", rl::po::value(&sched_policy),
       "CPU scheduling policy of the whole evaluator: normal, batch (no wake-up preemption) or "
       "idle (runs only on cycles nothing else wants). Default: the one it was started with")  //
      ("nice", rl::po::value(&nice),
       "nice value of the whole evaluator, 0 .. 19 (higher: lower priority, so that scoring does "
       "not take the learner's core: the CarRacing presets set 19; no effect under "
       "--sched-policy idle). Default: the one it was started with")  //
      ("run-config", rl::po::value(&run_config_file),
       "text file shown in the report as the run's config (default: the --config file)");

  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "evaluator", kUsage, desc, &vm)) return 0;
  // Before any thread starts: threads inherit the policy and nice value of their creator. What
  // is not given stays as inherited (raising a lowered priority back would need privileges).
  if (vm.count("sched-policy") > 0 || vm.count("nice") > 0) {
    rl::evaluator::Scheduling scheduling = rl::evaluator::CurrentScheduling();
    if (vm.count("sched-policy") > 0) {
      scheduling.policy = rl::evaluator::ParseSchedPolicy(sched_policy);
    }
    if (vm.count("nice") > 0) scheduling.nice = rl::evaluator::CheckNice(nice);
    rl::evaluator::ApplyScheduling(scheduling);
  }
  if (!eval_env.empty()) {
    // A run's networks take its env's observations and actions: an eval-env of another shape
    // (e.g. without CarRacing's pedals=1) could score none of its checkpoints.
    if (!vm["env"].defaulted() &&
        !rl::envs::SameShape(rl::envs::LookupSpec(config.env_id), rl::envs::LookupSpec(eval_env))) {
      throw std::invalid_argument("eval-env " + eval_env +
                                  " does not take the observations and actions of the run's env " +
                                  config.env_id);
    }
    config.env_id = eval_env;
  }
  if (rl::envs::LookupSpec(config.env_id).continuous()) {
    rl::RefuseGiven(vm, {"epsilon"},
                    config.env_id + " has continuous actions, scored without exploration");
  } else {
    rl::RefuseGiven(vm, {"noise"}, config.env_id + " has discrete actions (see --epsilon)");
  }
  // Standalone, only a command line's --ensemble scores an ensemble: a preset's `ensemble` key
  // is the service's.
  const bool standalone_ensemble =
      !checkpoint.empty() && rl::OnCommandLine(argc, argv, desc, "ensemble");
  if (!checkpoint.empty() && !standalone_ensemble) config.ensemble = 1;
  if (checkpoint.empty()) {
    rl::RefuseGiven(vm, {"noise"}, "the service scores without noise, the standard metric");
  }
  if (standalone_ensemble) {
    rl::RefuseGiven(vm, {"noise", "frames", "tsne-map"},
                    "not with --ensemble, which scores several networks as one");
  }
  if (!average_file.empty() && (!standalone_ensemble || config.ensemble_by != "weights")) {
    throw std::invalid_argument(
        "--save-average needs --checkpoint, --ensemble K and --ensemble-by weights");
  }
  if (!(noise_sigma >= 0 && std::isfinite(noise_sigma))) {
    throw std::invalid_argument("--noise must be finite and >= 0");
  }

  // Standalone mode: one file, one JSON object.
  if (standalone_ensemble) {
    config.Validate();
    const std::vector<std::string> files =
        rl::evaluator::EnsembleFiles(checkpoint, config.ensemble);
    std::string names;
    for (const std::string& f : files) {
      names += (names.empty() ? "" : ", ") + std::filesystem::path(f).filename().string();
    }
    const bool weights = config.ensemble_by == "weights";
    std::fprintf(stderr, "evaluator: the mean %s of %d checkpoints: %s\n",
                 weights ? "weights" : "action", config.ensemble, names.c_str());
    rl::evaluator::EvalRecord record;
    if (weights) {
      std::vector<rl::nn::Checkpoint> members;
      for (const std::string& f : files) members.push_back(rl::nn::LoadCheckpoint(f));
      const rl::nn::Checkpoint average = rl::evaluator::AverageCheckpoints(members, files);
      record = rl::evaluator::ScoreCheckpoint(average, checkpoint, config.env_id, config.episodes,
                                              config.epsilon, config.seed_base, config.gamma);
      if (!average_file.empty()) {
        rl::nn::SaveCheckpoint(average_file, average);
        std::fprintf(stderr, "evaluator: wrote the averaged network to %s\n", average_file.c_str());
      }
    } else {
      record = rl::evaluator::ScoreEnsembleFiles(files, config.env_id, config.episodes,
                                                 config.seed_base, config.gamma);
    }
    record.checkpoint = checkpoint;
    std::cout << rl::evaluator::ToJson(record) << std::endl;
    return 0;
  }
  if (!checkpoint.empty()) {
    config.Validate();
    rl::evaluator::EvalRecord record = rl::evaluator::ScoreCheckpointFile(
        checkpoint, config.env_id, config.episodes, config.epsilon, config.seed_base, config.gamma,
        {}, noise_sigma);
    record.checkpoint = checkpoint;
    std::cout << rl::evaluator::ToJson(record) << std::endl;
    if (!frames_file.empty()) {
      rl::nn::Sequential net = rl::evaluator::LoadPolicyNetwork(checkpoint, config.env_id);
      rl::evaluator::WriteFrameGrid(&net, config.env_id, config.seed_base,
                                    rl::evaluator::kFrameGridEpisodes,
                                    rl::evaluator::kFrameGridColumns, frames_file);
    }
    if (!tsne_file.empty()) WriteTsneMapOfCheckpoint(checkpoint, config, vm, tsne_file);
    return 0;
  }

  // Service mode.
  if (config.out_dir.empty()) {
    throw std::invalid_argument("--out DIR is required in service mode (or give --checkpoint)");
  }
  if (vm.count("goal") > 0) config.goal = goal;
  if (!run_config_file.empty()) {
    config.run_config_text = ReadTextFile(run_config_file);
  } else if (!common.config_file.empty()) {
    config.run_config_text = ReadTextFile(common.config_file);
  }
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("evaluator"));
  rl::evaluator::EvaluatorService service(config, &bus, stdout);
  std::printf("evaluator: scheduling %s\n", rl::evaluator::DescribeCurrent().c_str());
  std::printf("evaluator: ready\n");
  std::fflush(stdout);
  service.Run();
  std::printf("%s\n", service.FinalLine().c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("evaluator", Main, argc, argv); }
