// Replay throughput through LCM (udpm on loopback, the URLs of a run): a replay service in its
// own thread with its own LCM sockets, and in the main thread an "actor" publishing batches of
// 32 CartPole transitions as fast as it can, then a "learner" keeping 8 requests of 128
// transitions in flight. Reports inserts/s (transitions stored per second, with the share lost)
// and samples/s (transitions received by the learner per second). Rate limiting is off.
//
// Usage: bench_replay [repeats] [seconds] [port]   (run it in its own network namespace, or
// give it a free port)
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_util.h"
#include "common/channels.h"
#include "common/clock.h"
#include "replay/replay_service.h"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_replay_t.hpp"

namespace {

rl::BusConfig Config(int port, const std::string& sender) {
  rl::BusConfig c;
  c.url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
  c.bulk_url = "udpm://239.255.76.67:" + std::to_string(port + 1) + "?ttl=0&recv_buf_size=4194304";
  c.run_id = 77;
  c.sender = sender;
  return c;
}

rlmsg::transition_batch_t Batch() {
  rlmsg::transition_batch_t m{};
  m.obs_size = 4;
  m.count = 32;
  m.num_values = 128;
  m.obs.assign(128, 0.1f);
  m.next_obs.assign(128, 0.2f);
  m.action.assign(32, 1);
  m.reward.assign(32, 1.0f);
  m.discount.assign(32, 0.99f);
  m.episode_id.assign(32, 0);
  m.priority.assign(32, 0.0f);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 5;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 1.0;
  const int port = argc > 3 ? std::atoi(argv[3]) : 17667;

  // The replay service, on its own thread and sockets.
  std::atomic<bool> stop{false};
  std::atomic<int64_t> inserted{0};
  std::thread service_thread([&] {
    rl::Bus bus(Config(port, "replay"));
    rl::replay::ReplayServiceOptions o;
    o.table.capacity = 1'000'000;
    o.limiter.samples_per_insert = 0;  // no rate limiting
    o.limiter.min_size_to_sample = 128;
    o.stats_hz = 20;
    rl::replay::ReplayService service(&bus, o);
    service.Run([&] {
      inserted.store(service.table().total_inserts());
      return stop.load();
    });
  });

  rl::Bus bus(Config(port, "learner"));
  int64_t received = 0;
  int64_t in_flight = 0;
  bus.Subscribe<rlmsg::sample_batch_t>(
      rl::channels::kSamples,
      [&](const rlmsg::sample_batch_t& m) {
        received += m.count;
        --in_flight;
      },
      rl::Port::kBulk);
  bool replay_up = false;
  bus.Subscribe<rlmsg::stats_replay_t>(rl::channels::kStatsReplay,
                                       [&](const rlmsg::stats_replay_t&) { replay_up = true; });
  const double ready_deadline = rl::MonoSeconds() + 10;
  while (!replay_up && rl::MonoSeconds() < ready_deadline) bus.Handle(50);
  if (!replay_up) {
    std::fprintf(stderr, "bench_replay: the replay service did not come up\n");
    stop = true;
    service_thread.join();
    return 1;
  }

  // Inserts: publish batches back to back for `seconds`, then wait until the count settles.
  rlmsg::transition_batch_t batch = Batch();
  std::vector<double> insert_rates, loss;
  for (int r = 0; r < repeats; ++r) {
    const int64_t before = inserted.load();
    int64_t sent = 0;
    const double start = rl::MonoSeconds();
    while (rl::MonoSeconds() - start < seconds) {
      bus.Publish(rl::channels::kTransitions, &batch);
      sent += batch.count;
      bus.Handle(0);
    }
    int64_t last = -1;
    double settled = rl::MonoSeconds();
    while (true) {
      bus.Handle(20);
      const int64_t now_count = inserted.load();
      if (now_count != last) {
        last = now_count;
        settled = rl::MonoSeconds();
      } else if (rl::MonoSeconds() - settled > 0.3 || now_count - before >= sent) {
        break;
      }
    }
    const double elapsed = settled - start;  // until the last insert was seen
    insert_rates.push_back(static_cast<double>(last - before) / elapsed);
    loss.push_back(100.0 * static_cast<double>(sent - (last - before)) / static_cast<double>(sent));
  }
  const auto loss_s = rl::bench::Summarize(loss);
  char extra[160];
  std::snprintf(extra, sizeof(extra),
                "\"batch\": 32, \"transport\": \"udpm\", \"lost_percent_median\": %.3f, "
                "\"lost_percent_max\": %.3f",
                loss_s.median, loss_s.max);
  rl::bench::Emit("replay_inserts_lcm", "transitions/s", rl::bench::Summarize(insert_rates),
                  repeats, extra);

  // Samples: keep 8 requests of 128 in flight.
  int64_t next_id = 0;
  auto measure = [&] {
    const int64_t before = received;
    const double start = rl::MonoSeconds();
    double last_send = start;
    while (rl::MonoSeconds() - start < seconds) {
      const double now = rl::MonoSeconds();
      if (now - last_send > 0.5) in_flight = 0;  // a lost reply: send again
      while (in_flight < 8) {
        rlmsg::sample_request_t req{};
        req.request_id = next_id++;
        req.batch_size = 128;
        bus.Publish(rl::channels::kSampleRequest, &req);
        ++in_flight;
        last_send = now;
      }
      bus.Handle(1);
    }
    return static_cast<double>(received - before) / (rl::MonoSeconds() - start);
  };
  rl::bench::Emit("replay_samples_lcm", "transitions/s", rl::bench::Repeat(repeats, measure),
                  repeats, "\"batch\": 128, \"in_flight\": 8, \"transport\": \"udpm\"");
  stop = true;
  service_thread.join();
  return 0;
}
