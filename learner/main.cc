// The learner process: see learner/learner.h and learner/README.md.
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/options.h"
#include "common/shutdown.h"
#include "learner/learner.h"

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
  rl::learner::DqnConfig& d = c.dqn;
  std::string hidden = "120,84";
  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()                                                                //
      ("env", rl::po::value(&c.env_id)->default_value(c.env_id), "environment id")  //
      ("out", rl::po::value(&c.out_dir)->default_value(c.out_dir),
       "run folder; checkpoints go to <out>/checkpoints")  //
      ("network", rl::po::value(&d.network)->default_value(d.network),
       "Q network: mlp, nature (Mnih et al. 2015, 4x84x84 frames), grasp (stacks of 40x40 "
       "frames), grasp48 (stacks of 48x48 frames, a 6x6 map) or an architecture string")  //
      ("hidden", rl::po::value(&hidden)->default_value(hidden),
       "hidden layer widths of the MLP")  //
      ("dueling", rl::po::value(&d.dueling)->default_value(d.dueling),
       "dueling value and advantage streams (1/0; mlp, nature, grasp, grasp48)")  //
      ("prioritized", rl::po::value(&c.prioritized)->default_value(c.prioritized),
       "send |TD errors| to the replay as priorities after every update (1/0)")  //
      ("batch-size", rl::po::value(&c.batch_size)->default_value(c.batch_size),
       "transitions per update")                                                                 //
      ("optimizer", rl::po::value(&d.optimizer)->default_value(d.optimizer), "adam or rmsprop")  //
      ("learning-rate", rl::po::value(&d.learning_rate)->default_value(d.learning_rate),
       "step size")                                                                        //
      ("adam-eps", rl::po::value(&d.adam_eps)->default_value(d.adam_eps), "Adam epsilon")  //
      ("rmsprop-alpha", rl::po::value(&d.rmsprop_alpha)->default_value(d.rmsprop_alpha),
       "RMSProp smoothing constant (DeepMind: 0.95)")  //
      ("rmsprop-eps", rl::po::value(&d.rmsprop_eps)->default_value(d.rmsprop_eps),
       "RMSProp epsilon (DeepMind: 0.01)")  //
      ("rmsprop-centered", rl::po::value(&d.rmsprop_centered)->default_value(d.rmsprop_centered),
       "centered RMSProp, as DeepMind's (1/0)")                                //
      ("loss", rl::po::value(&d.loss)->default_value(d.loss), "huber or mse")  //
      ("double-dqn", rl::po::value(&d.double_dqn)->default_value(d.double_dqn),
       "Double DQN targets (1/0)")  //
      ("target-update-period",
       rl::po::value(&d.target_update_period)->default_value(d.target_update_period),
       "updates between target network refreshes")  //
      ("tau", rl::po::value(&d.tau)->default_value(d.tau),
       "refresh weight of the online network (1: hard copy)")  //
      ("max-grad-norm", rl::po::value(&d.max_grad_norm)->default_value(d.max_grad_norm),
       "gradient norm clip (0: none)")  //
      ("augment-shift", rl::po::value(&d.augment_shift)->default_value(d.augment_shift),
       "pixel envs: shift every sampled observation by a random offset of up to this many "
       "pixels, edges repeated (DrQ, Kostrikov et al. 2020); 0: none")                //
      ("seed", rl::po::value(&d.seed)->default_value(d.seed), "initialisation seed")  //
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
       "newest checkpoint files kept on disk (0: all)")  //
      ("threads", rl::po::value(&c.threads)->default_value(c.threads),
       "compute threads for the network (convolutions and large products are split; 1 leaves "
       "the other cores to the actors)")  //
      ("max-updates", rl::po::value(&c.max_updates)->default_value(c.max_updates),
       "stop after this many updates (0: until stopped)")  //
      ("stats-hz", rl::po::value(&c.stats_hz)->default_value(c.stats_hz),
       "stats messages per second");
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "learner",
                        "Usage: learner [options]\n"
                        "Trains a DQN on batches sampled from the replay daemon, broadcasts its "
                        "weights and writes checkpoints.",
                        desc, &vm)) {
    return 0;
  }
  d.hidden = ParseWidths(hidden);
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("learner"));
  rl::learner::Learner learner(c, &bus);
  std::string shifts;
  if (const int k = learner.dqn().config().augment_shift; k > 0) {
    shifts = ", random shifts of up to " + std::to_string(k) + " pixels";
  }
  std::printf("learner: ready (%s)%s\n", learner.dqn().online().Architecture().c_str(),
              shifts.c_str());
  std::fflush(stdout);
  learner.Run();
  std::printf("learner: stopped after %lld updates\n", static_cast<long long>(learner.updates()));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("learner", Main, argc, argv); }
