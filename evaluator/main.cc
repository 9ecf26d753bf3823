// The evaluator: scores the checkpoints of a run and writes its report (service mode), or scores
// one checkpoint file (standalone mode). See README.md.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/lcm_bus.h"
#include "common/options.h"
#include "common/shutdown.h"
#include "envs/specs.h"
#include "evaluator/evaluator_service.h"
#include "evaluator/frame_grid.h"
#include "evaluator/report.h"

namespace {

constexpr char kUsage[] =
    "Usage:\n"
    "  evaluator --out DIR [options]\n"
    "      Service mode: scores every checkpoint the learner announces on RL_CHECKPOINT (the\n"
    "      newest first; older unscored ones are skipped), appends DIR/eval.jsonl, rewrites\n"
    "      DIR/report/index.html and its learning curves, publishes RL_EVAL and\n"
    "      RL_STATS_EVALUATOR. Prints 'evaluator: ready' once subscribed. Stops on SIGINT or\n"
    "      SIGTERM, or with --stop-at-goal once a checkpoint reaches the goal, and then prints\n"
    "      'evaluator: goal reached' or 'evaluator: goal not reached (best X)'; exit status 0.\n"
    "  evaluator --checkpoint FILE [--env ID] [--episodes N] [--epsilon E] [--seed-base S]\n"
    "            [--gamma G] [--frames PNG]\n"
    "      Standalone mode: scores one checkpoint file and prints one JSON object (checkpoint,\n"
    "      update, env_steps, wall_seconds, mean, std, min, max, episodes, eval_seconds, and\n"
    "      value_steps, value_estimate, value_return, value_correlation: the network's value\n"
    "      estimates of the actions taken against the discounted returns that followed).\n"
    "      --frames also writes the grid of camera frames the report shows (pixel envs).\n"
    "      A refused file prints 'evaluator: error: <reason>' and exits with status 2.\n"
    "\n"
    "Episode i of an evaluation is reset with seed seed-base + i; the default seed base is far\n"
    "above the seeds actors train with, so evaluation never replays a training seed.";

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  rl::evaluator::EvaluatorConfig config;
  std::string checkpoint;
  std::string run_config_file;
  std::string eval_env;
  std::string frames_file;
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
      ("run-config", rl::po::value(&run_config_file),
       "text file shown in the report as the run's config (default: the --config file)");

  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "evaluator", kUsage, desc, &vm)) return 0;
  if (!eval_env.empty()) config.env_id = eval_env;
  if (rl::envs::LookupSpec(config.env_id).continuous()) {
    rl::RefuseGiven(vm, {"epsilon"},
                    config.env_id + " has continuous actions, scored without exploration");
  }

  // Standalone mode: one file, one JSON object.
  if (!checkpoint.empty()) {
    config.Validate();
    rl::evaluator::EvalRecord record = rl::evaluator::ScoreCheckpointFile(
        checkpoint, config.env_id, config.episodes, config.epsilon, config.seed_base, config.gamma);
    record.checkpoint = checkpoint;
    std::cout << rl::evaluator::ToJson(record) << std::endl;
    if (!frames_file.empty()) {
      rl::nn::Sequential net = rl::evaluator::LoadPolicyNetwork(checkpoint, config.env_id);
      rl::evaluator::WriteFrameGrid(&net, config.env_id, config.seed_base,
                                    rl::evaluator::kFrameGridEpisodes,
                                    rl::evaluator::kFrameGridColumns, frames_file);
    }
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
  std::printf("evaluator: ready\n");
  std::fflush(stdout);
  service.Run();
  std::printf("%s\n", service.FinalLine().c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("evaluator", Main, argc, argv); }
