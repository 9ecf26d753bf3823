// The actor process: see actor/actor.h and actor/README.md.
#include <cstdio>
#include <string>

#include "actor/actor.h"
#include "common/options.h"
#include "common/shutdown.h"

namespace {

int Main(int argc, char** argv) {
  rl::CommonOptions common;
  rl::actor::ActorConfig c;
  rl::po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  auto& e = c.exploration;
  desc.add_options()                                                                //
      ("env", rl::po::value(&c.env_id)->default_value(c.env_id), "environment id")  //
      ("actor-id", rl::po::value(&c.actor_id)->default_value(c.actor_id),
       "index of this actor, 0 .. num-actors - 1")  //
      ("num-actors", rl::po::value(&c.num_actors)->default_value(c.num_actors),
       "actors in the run (sets the Ape-X epsilons)")  //
      ("envs-per-actor", rl::po::value(&c.envs_per_actor)->default_value(c.envs_per_actor),
       "environments stepped in turn by this actor")                       //
      ("seed", rl::po::value(&c.seed)->default_value(c.seed), "run seed")  //
      ("batch-size", rl::po::value(&c.batch_size)->default_value(c.batch_size),
       "transitions per published message")                                                     //
      ("n-step", rl::po::value(&c.n_step)->default_value(c.n_step), "n of the n-step returns")  //
      ("gamma", rl::po::value(&c.gamma)->default_value(c.gamma), "discount factor")             //
      ("exploration", rl::po::value(&e.mode)->default_value(e.mode),
       "discrete actions (epsilon-greedy): apex (constant epsilon_i = base^(1 + alpha "
       "i/(N-1))), linear (annealed), constant; continuous actions: gaussian (noise on the "
       "actor network's action, clipped to the bounds)")  //
      ("apex-base", rl::po::value(&e.apex_base)->default_value(e.apex_base),
       "Ape-X base epsilon")  //
      ("apex-alpha", rl::po::value(&e.apex_alpha)->default_value(e.apex_alpha),
       "Ape-X exponent spread")  //
      ("epsilon-start", rl::po::value(&e.start)->default_value(e.start),
       "linear: first epsilon")  //
      ("epsilon-end", rl::po::value(&e.end)->default_value(e.end),
       "linear: final epsilon; constant: the epsilon")  //
      ("epsilon-anneal-steps", rl::po::value(&e.anneal_steps)->default_value(e.anneal_steps),
       "linear: steps from start to end")  //
      ("sigma", rl::po::value(&e.sigma)->default_value(e.sigma),
       "gaussian: noise standard deviation, relative to each dimension's half-range (TD3: "
       "0.1)")  //
      ("sigma-end", rl::po::value(&e.sigma_end)->default_value(e.sigma_end),
       "gaussian: final noise scale when annealed")  //
      ("sigma-anneal-steps",
       rl::po::value(&e.sigma_anneal_steps)->default_value(e.sigma_anneal_steps),
       "gaussian: steps of this actor from sigma to sigma-end (0: sigma throughout)")  //
      ("noise-spread", rl::po::value(&e.noise_spread)->default_value(e.noise_spread),
       "gaussian: actor i of N uses sigma * spread^(i/(N-1)) (1: every actor alike)")  //
      ("start-steps", rl::po::value(&e.start_steps)->default_value(e.start_steps),
       "gaussian: uniform random actions for this actor's first steps")  //
      ("stats-hz", rl::po::value(&c.stats_hz)->default_value(c.stats_hz),
       "stats messages per second")  //
      ("clip-rewards", rl::po::value(&c.clip_rewards)->default_value(c.clip_rewards),
       "clamp rewards to [-1, 1] in transitions, as Mnih et al. 2015 (1/0; returns in the stats "
       "stay unclipped)")  //
      ("max-steps", rl::po::value(&c.max_steps)->default_value(c.max_steps),
       "stop after this many env steps (0: until stopped)")  //
      ("later-env", rl::po::value(&c.later_env_id),
       "environment id of the episodes that begin after --later-env-after steps of this actor "
       "(a schedule of training rules, e.g. CarRacing's off-track rule dropped once the policy "
       "drives); it must give the observations and actions --env gives")  //
      ("later-env-after", rl::po::value(&c.later_env_after)->default_value(c.later_env_after),
       "with --later-env: steps of this actor (its earlier lives included) before its episodes "
       "begin on the later env");
  rl::po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "actor",
                        "Usage: actor [options]\n"
                        "Runs environments with an exploring policy (epsilon-greedy for discrete "
                        "actions, Gaussian noise for continuous ones) and publishes their "
                        "transitions to the replay daemon over LCM.",
                        desc, &vm)) {
    return 0;
  }
  if (e.gaussian()) {
    rl::RefuseGiven(
        vm, {"apex-base", "apex-alpha", "epsilon-start", "epsilon-end", "epsilon-anneal-steps"},
        "exploration is gaussian, and it is an epsilon-greedy option");
  } else {
    rl::RefuseGiven(vm, {"sigma", "sigma-end", "sigma-anneal-steps", "noise-spread", "start-steps"},
                    "exploration is " + e.mode + " (epsilon-greedy), and it is a gaussian option");
  }
  if (c.later_env_id.empty()) {
    rl::RefuseGiven(vm, {"later-env-after"}, "no --later-env is given");
  }
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("actor-" + std::to_string(c.actor_id)));
  rl::actor::Actor actor(c, &bus);
  std::printf("actor-%d: ready (%s %.5f)\n", c.actor_id, e.gaussian() ? "sigma" : "epsilon",
              actor.exploration());
  std::fflush(stdout);
  actor.Run();
  std::printf("actor-%d: stopped after %lld steps, %lld episodes, weights %lld\n", c.actor_id,
              static_cast<long long>(actor.env_steps()), static_cast<long long>(actor.episodes()),
              static_cast<long long>(actor.weights_version()));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("actor", Main, argc, argv); }
