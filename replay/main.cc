// The replay daemon: stores the actors' transitions and answers the learner's sample requests,
// holding both to a samples-per-insert ratio. See README.md.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>

#include "common/clock.h"
#include "common/lcm_bus.h"
#include "common/options.h"
#include "common/shutdown.h"
#include "envs/specs.h"
#include "replay/replay_service.h"
#include "replay/snapshotter.h"

namespace {

constexpr char kUsage[] =
    "Usage: replay [options]\n"
    "The replay daemon: stores transitions from RL_TRANSITIONS in a ring buffer and answers\n"
    "RL_SAMPLE_REQUEST with batches on RL_SAMPLES (uniform or prioritized; flat observations,\n"
    "or pixel frames stored once and stacks rebuilt), holding the ratio of samples to inserts\n"
    "near --samples-per-insert (actors are paused through RL_FLOW). With --env, every action is\n"
    "checked against the env's action space (width, integer indices, bounds) and a batch with a\n"
    "bad one is refused and counted.\n"
    "With --snapshot PATH, the replay loads PATH at its start when it exists (a file that is not\n"
    "a replay snapshot of this run and configuration, or is torn or corrupted, is refused: the\n"
    "replay exits with status 2 and says why) and writes its whole state there every\n"
    "--snapshot-every seconds from a forked child (copy-on-write; the service pauses for the fork\n"
    "only), and once more when it stops.";

int Main(int argc, char** argv) {
  namespace po = rl::po;
  rl::CommonOptions common;
  rl::replay::ReplayServiceOptions options;
  options.progress_seconds = 5.0;
  std::string env_id;
  rl::replay::SnapshotterOptions snapshots;

  po::options_description desc("Options");
  rl::AddCommonOptions(&desc, &common);
  desc.add_options()  //
      ("env", po::value(&env_id),
       "environment of the run: its static spec picks the table (flat observations of its "
       "size, or its frames) and actions are checked against its action space (none: the first "
       "batch decides, any action of its width)")  //
      ("capacity", po::value(&options.table.capacity)->default_value(options.table.capacity),
       "transitions kept; the oldest are overwritten")  //
      ("obs-size", po::value(&options.table.obs_size)->default_value(options.table.obs_size),
       "floats per observation (0: the flat env's with --env, else from the first batch); other "
       "sizes are refused")  //
      ("min-size",
       po::value(&options.limiter.min_size_to_sample)
           ->default_value(options.limiter.min_size_to_sample),
       "transitions inserted before the first sample")  //
      ("samples-per-insert",
       po::value(&options.limiter.samples_per_insert)
           ->default_value(options.limiter.samples_per_insert),
       "target transitions sampled per transition inserted (<= 0: no ratio, only --min-size)")  //
      ("error-buffer",
       po::value(&options.limiter.error_buffer)->default_value(options.limiter.error_buffer),
       "tolerated deviation from the ratio, in samples: actors may run error-buffer / "
       "samples-per-insert transitions ahead, the learner error-buffer samples ahead")  //
      ("seed", po::value(&options.seed)->default_value(options.seed),
       "seed of the sampler")  //
      ("prioritized", po::value(&options.prioritized)->default_value(options.prioritized),
       "sample in proportion to priority (Schaul et al. 2016) instead of uniformly")  //
      ("alpha", po::value(&options.alpha)->default_value(options.alpha),
       "priority exponent: P(i) ~ (priority_i + priority-epsilon)^alpha")  //
      ("beta", po::value(&options.beta)->default_value(options.beta),
       "initial importance-sampling exponent, annealed linearly to 1")  //
      ("beta-anneal-samples",
       po::value(&options.beta_anneal_samples)->default_value(options.beta_anneal_samples),
       "sampled transitions over which beta reaches 1 (0: beta stays constant)")  //
      ("priority-epsilon",
       po::value(&options.priority_epsilon)->default_value(options.priority_epsilon),
       "added to every priority, so that no transition has probability 0")  //
      ("frame-capacity", po::value(&options.frame_capacity)->default_value(options.frame_capacity),
       "pixel frames kept (0: capacity * 1.03125 + 4096, for episodes of 32 steps or more)")  //
      ("max-pending-requests",
       po::value(&options.max_pending_requests)->default_value(options.max_pending_requests),
       "sample requests held while the rate limiter waits; the oldest is dropped beyond")  //
      ("flow-hz", po::value(&options.flow_hz)->default_value(options.flow_hz),
       "RL_FLOW messages per second (and at once on every change)")  //
      ("stats-hz", po::value(&options.stats_hz)->default_value(options.stats_hz),
       "RL_STATS_REPLAY messages per second")  //
      ("max-actors", po::value(&options.max_actors)->default_value(options.max_actors),
       "actor ids stored: 0 .. max-actors - 1 (at most 1024); batches of other ids are refused "
       "and counted")  //
      ("snapshot", po::value(&snapshots.path),
       "snapshot file: loaded at the start when it exists, written every --snapshot-every "
       "seconds and at the end (none: no snapshots)")  //
      ("snapshot-every",
       po::value(&snapshots.every_seconds)->default_value(snapshots.every_seconds),
       "seconds between snapshots: after a crash, at most the transitions of this long are "
       "lost");
  po::variables_map vm;
  if (!rl::ParseOptions(argc, argv, "replay", kUsage, desc, &vm)) return 0;

  if (!env_id.empty()) {
    // The static spec: the replay builds no env and links no physics.
    const rl::envs::EnvSpec spec = rl::envs::LookupSpec(env_id);
    // The table of the env's observations: flat floats, or frames stored once.
    if (spec.frame_stack > 0) {
      options.kind = rl::replay::TableKind::kPixels;
      options.frames = {0, spec.frame_height, spec.frame_width, spec.frame_stack};
    } else {
      options.kind = rl::replay::TableKind::kFlat;
      if (options.table.obs_size == 0) options.table.obs_size = spec.observation_size;
    }
    options.table.action_width = spec.action_width();
    options.check_action = [spec](std::span<const float> action) {
      return rl::envs::CheckAction(spec, action);
    };
  }
  // Refuse bad values before touching the network.
  options.Validate();
  snapshots.Validate();
  rl::InstallStopHandlers();
  rl::Bus bus(common.MakeBusConfig("replay"));
  rl::replay::ReplayService service(&bus, options);
  // The last snapshot, if any: a file that is there but refused ends the daemon (status 2).
  if (!snapshots.path.empty()) {
    if (std::filesystem::exists(snapshots.path)) {
      const double start = rl::MonoSeconds();
      const std::string loaded = service.LoadSnapshot(snapshots.path);
      std::printf("replay: snapshot %s loaded (%s) in %.2f s\n", snapshots.path.c_str(),
                  loaded.c_str(), rl::MonoSeconds() - start);
    } else {
      std::printf("replay: no snapshot %s yet; starting empty\n", snapshots.path.c_str());
    }
  }
  rl::replay::Snapshotter snapshotter(
      snapshots, rl::replay::ReplayService::kSnapshotKind,
      [&service](rl::StateStream* out) { return service.SaveSnapshot(out); },
      [&service, &bus] {
        // Any message taken moves the bus's positions, which the snapshot keeps.
        return service.total_inserts() + service.total_samples() +
               service.counters().priorities_applied + bus.counters().received;
      });
  std::printf("replay: ready\n");
  std::fflush(stdout);

  // Between rounds: reap the last snapshot's writer, and start the next one when it is due.
  service.Run([&snapshotter] {
    snapshotter.Tick(rl::MonoSeconds());
    return rl::StopRequested();
  });
  snapshotter.Finish();
  std::printf("replay: stopped after %lld inserts and %lld samples\n",
              static_cast<long long>(service.total_inserts()),
              static_cast<long long>(service.total_samples()));
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rl::RunMain("replay", Main, argc, argv); }
