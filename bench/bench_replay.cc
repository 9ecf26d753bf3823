// Replay throughput through LCM (udpm on loopback, the URLs of a run), and the memory of pixel
// replay.
//
// Flat (CartPole) transitions: a replay service in its own thread with its own LCM sockets, and
// in the main thread an "actor" publishing batches of 32 CartPole transitions as fast as it can,
// then a "learner" keeping 8 requests of 128 transitions in flight. Reports inserts/s
// (transitions stored per second, with the share lost) and samples/s (transitions received by
// the learner per second). Rate limiting is off.
//
// Pixel (Nature DQN: 84 x 84 grayscale frames, stacks of 4) transitions, into a second replay
// service (capacity 100,000, rate limiting off) on its own two ports:
//   pixel_replay_insert       batches of 32 transitions with their new frames, built as
//                             actor/actor.cc builds them (each frame sent once with an increasing
//                             actor-local id, stacks named by frame ids, the first frame of an
//                             episode repeated to fill the stack), published back to back from
//                             the main thread; transitions/s and MB/s stored, and what was lost.
//   pixel_replay_sample       the learner's path: 4 requests of 32 stacks in flight (the
//                             learner's default), replies of ~1.8 MB on the samples port.
//   pixel_replay_8_actors     8 actor threads, each with its own bus, each publishing a batch
//                             every 32 / 250 s (250 env steps/s per actor: an assumed nominal
//                             rate for an Atari-like env with a Nature CNN policy on one core,
//                             not measured here) for a few seconds, into the same service, nobody
//                             sampling; transitions lost and delivered per second.
//                             pixel_replay_8_actors_4x: the same at 4x, to show the headroom.
//   pixel_replay_bytes_per_transition[_prioritized]  a PixelTable (no LCM) filled with 100,000
//                             transitions from 8 simulated actors: memory_bytes() / size(), and
//                             the process's VmRSS growth around filling it.
//
// Authenticated messages (common/message_auth.h):
//   mac_aes256_gmac_{pixel_batch,4mb}  checking the MAC of a 230 KB and of a 4 MB message, MB/s
//                             (mac_hmac_sha256_*: HMAC-SHA256 over the same bytes, for
//                             comparison).
//   bus_receive_real_{flat,pixel}, bus_drop_forged_{flat,pixel}  what a keyed bus spends on one
//                             message from its arrival to its handler (Bus::Deliver, no
//                             transport), µs: a real CartPole or pixel batch (header, MAC,
//                             freshness, decode, Validate) against a forged one of the same size
//                             (a wrong MAC, a sender name and incarnation of its own each: dropped
//                             after the MAC check); the forged row gives the ratio.
//   pixel_replay_insert_mac   pixel_replay_insert with the run's key on both sides (the actor
//                             signs, the replay checks), on two more ports: compare its rate and
//                             replay_cpu_us_per_transition with pixel_replay_insert's.
//   pixel_replay_8_actors_4x_mac  pixel_replay_8_actors_4x with the key.
//   pixel_replay_insert_cpu[_mac]  the replay's CPU time per stored pixel transition (every
//                             thread of a replay process of its own), one actor publishing at a
//                             paced 100,000 transitions/s, without and with the key, in
//                             alternating windows; the _mac row also gives the share of the
//                             replay's CPU time its MAC checks took (PixelInsertCpu below).
//
// Snapshots (replay/snapshotter.h: fork, then the child writes), of a CarRacing-size pixel table
// (capacity 100,000, frame capacity 130,000 of 84 x 84, prioritized; about 1 GB) and of a
// CartPole-size flat table (capacity 50,000, obs 4, uniform), both full, into files in the
// temporary directory:
//   replay_snapshot_pause_{pixel,flat}  the parent's pause (building the section list + fork()),
//                             in ms; with the file's bytes, the process's RSS and how much of it
//                             is in transparent huge pages (the pixel table's frame ring asks
//                             for them: replay/huge_page_allocator.h).
//   replay_snapshot_write_{pixel,flat}  the child's write (checksum, write, fsync, rename), in s;
//                             the parent goes on inserting meanwhile (copy-on-write faults), and
//                             its insert rate during the write and before it are given.
//
// Usage: bench_replay [repeats] [seconds] [port]   (run it in its own network namespace, or
// give it four free ports from `port` on)
//        bench_replay --snapshots [repeats]        the snapshot rows only
//        bench_replay --mac [repeats] [seconds] [port]  the MAC rows only (below)
#include <malloc.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <new>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_util.h"
#include "bench/transition_batches.h"
#include "common/channels.h"
#include "common/check.h"
#include "common/clock.h"
#include "common/message_auth.h"
#include "replay/pixel_table.h"
#include "replay/prioritized_sampler.h"
#include "replay/replay_service.h"
#include "replay/replay_table.h"
#include "replay/snapshotter.h"
#include "replay/uniform_sampler.h"
#include "rlmsg/flow_control_t.hpp"
#include "rlmsg/sample_request_t.hpp"
#include "rlmsg/stats_replay_t.hpp"

namespace {

rl::BusConfig Config(int port, const std::string& sender, const std::string& key = "") {
  rl::BusConfig c;
  c.key = key;
  c.url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
  c.bulk_url = "udpm://239.255.76.67:" + std::to_string(port + 1) + "?ttl=0&recv_buf_size=4194304";
  c.samples_url =
      "udpm://239.255.76.67:" + std::to_string(port + 2) + "?ttl=0&recv_buf_size=4194304";
  c.run_id = 77;
  c.sender = sender;
  return c;
}

// Waits up to 10 s for the replay service's first stats message: its readiness.
bool WaitForReplay(rl::Bus* bus) {
  // Shared with the subscription, which outlives this call.
  auto replay_up = std::make_shared<bool>(false);
  bus->Subscribe<rlmsg::stats_replay_t>(
      rl::channels::kStatsReplay, [replay_up](const rlmsg::stats_replay_t&) { *replay_up = true; });
  const double ready_deadline = rl::MonoSeconds() + 10;
  while (!*replay_up && rl::MonoSeconds() < ready_deadline) bus->Handle(50);
  return *replay_up;
}

// Flat CartPole transitions: replay_inserts_lcm and replay_samples_lcm, on `port` to port + 2.
int RunFlat(int repeats, double seconds, int port) {
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
      inserted.store(service.total_inserts());
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
      rl::Port::kSamples);
  if (!WaitForReplay(&bus)) {
    std::fprintf(stderr, "bench_replay: the replay service did not come up\n");
    stop = true;
    service_thread.join();
    return 1;
  }

  // Inserts: publish batches back to back for `seconds`, then wait until the count settles.
  rlmsg::transition_batch_t batch = rl::bench::FlatBatch();
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

// ---------------------------------------------------------------------------------------------
// Pixel transitions.

using rl::bench::kBatch;
using rl::bench::kFrameBytes;
using rl::bench::kHeight;
using rl::bench::kMaxEpisode;
using rl::bench::kMinEpisode;
using rl::bench::kStack;
using rl::bench::kWidth;
using rl::bench::PixelActorSim;

constexpr int kActors = 8;
constexpr double kStepsPerActor = 250;    // assumed env steps/s of one actor (see the top)
constexpr int64_t kCapacity = 100'000;    // transitions kept by the pixel replay service
constexpr int64_t kMemoryFill = 100'000;  // transitions put in the table of the memory figure
constexpr int kSampleInFlight = 4;        // the learner's default requests_in_flight

// What the pixel replay service's thread exposes to the main thread.
struct ServiceProbe {
  std::atomic<bool> stop{false};
  std::atomic<int64_t> inserts{0};             // transitions stored
  std::atomic<int64_t> missing_frames{0};      // transitions skipped for a frame never received
  std::atomic<int64_t> lost{0};                // sequence gaps counted by the service's bus
  std::atomic<int64_t> dropped{0};             // malformed, invalid or refused
  std::atomic<double> cpu_seconds{0};          // the service thread's CPU time
  std::atomic<double> process_cpu_seconds{0};  // the whole process's (all its threads)
  std::atomic<int64_t> mac_nanos{0};           // its bus's MAC time (checks, and its own signing)
};
static_assert(std::atomic<double>::is_always_lock_free && std::atomic<int64_t>::is_always_lock_free,
              "a ServiceProbe is shared with a forked service process");

// The MAC a bus with `key` signs and checks with, for the rows' "mac" field.
const char* MacName(const std::string& key) { return key.empty() ? "none" : "AES-256-GMAC"; }

// OpenSSL's AES-256-GCM with nothing encrypted (GMAC, as common/message_auth.h uses it) under one
// key, for MACs computed and dropped: what an unkeyed actor does to load the machine as a keyed
// one does.
class LooseGmac {
 public:
  LooseGmac() : ctx_(EVP_CIPHER_CTX_new()) {
    const std::string key(32, 's');
    if (ctx_ == nullptr ||
        EVP_EncryptInit_ex(ctx_, EVP_aes_256_gcm(), nullptr,
                           reinterpret_cast<const unsigned char*>(key.data()), nullptr) != 1) {
      std::fprintf(stderr, "bench_replay: no AES-256-GCM from OpenSSL\n");
      std::abort();
    }
  }
  LooseGmac(const LooseGmac&) = delete;
  LooseGmac& operator=(const LooseGmac&) = delete;
  ~LooseGmac() { EVP_CIPHER_CTX_free(ctx_); }

  // The tag of `size` bytes under a nonce made of `seq`.
  void Tag(int64_t seq, const uint8_t* data, size_t size, unsigned char* tag) {
    unsigned char nonce[12] = {};
    std::memcpy(nonce, &seq, sizeof(seq));
    int out = 0;
    if (EVP_EncryptInit_ex(ctx_, nullptr, nullptr, nullptr, nonce) != 1 ||
        EVP_EncryptUpdate(ctx_, nullptr, &out, data, static_cast<int>(size)) != 1 ||
        EVP_EncryptFinal_ex(ctx_, tag, &out) != 1 ||
        EVP_CIPHER_CTX_ctrl(ctx_, EVP_CTRL_GCM_GET_TAG, 16, tag) != 1) {
      std::abort();
    }
  }

 private:
  EVP_CIPHER_CTX* ctx_;
};

void PinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof(set), &set) != 0) std::perror("bench_replay: sched_setaffinity");
}

double CpuSeconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

void RunPixelService(int port, ServiceProbe* probe, const std::string& key) {
  rl::Bus bus(Config(port, "replay", key));
  rl::replay::ReplayServiceOptions o;
  o.table.capacity = kCapacity;
  o.limiter.samples_per_insert = 0;  // no rate limiting
  o.limiter.min_size_to_sample = 128;
  o.stats_hz = 20;
  rl::replay::ReplayService service(&bus, o);
  service.Run([&] {
    probe->inserts.store(service.total_inserts());
    probe->missing_frames.store(service.table().transitions_missing_frames());
    const rl::BusCounters& c = bus.counters();
    probe->lost.store(c.lost);
    probe->dropped.store(c.dropped() + service.counters().batches_refused);
    probe->cpu_seconds.store(CpuSeconds(CLOCK_THREAD_CPUTIME_ID));
    probe->process_cpu_seconds.store(CpuSeconds(CLOCK_PROCESS_CPUTIME_ID));
    probe->mac_nanos.store(c.mac_nanos);
    return probe->stop.load();
  });
}

// Handles the bus until the service's insert count reaches `target` or has not changed for
// `quiet` seconds; returns the count and sets *when to the time it last changed.
int64_t Settle(rl::Bus* bus, const ServiceProbe& probe, int64_t target, double quiet,
               double* when) {
  int64_t last = -1;
  *when = rl::MonoSeconds();
  while (true) {
    bus->Handle(20);
    const int64_t now_count = probe.inserts.load();
    if (now_count != last) {
      last = now_count;
      *when = rl::MonoSeconds();
    }
    if (now_count >= target || rl::MonoSeconds() - *when > quiet) return now_count;
  }
}

// pixel_replay_insert[_mac]: one actor's batches published back to back from the main thread.
// Also the replay thread's CPU time per stored transition (what a MAC adds to the replay's work,
// unlike the rate, which the transport's losses make noisy).
bool PixelInsert(rl::Bus* bus, const ServiceProbe& probe, int repeats, double seconds,
                 const char* name) {
  PixelActorSim sim(0, 1);

  // The first batch makes the service allocate its table (about 0.8 GB for 100,000 stacks).
  const double first_start = rl::MonoSeconds();
  double first_sent = 0;
  while (probe.inserts.load() == 0 && rl::MonoSeconds() - first_start < 10) {
    if (rl::MonoSeconds() - first_sent > 2) {
      bus->Publish(rl::channels::kTransitions, sim.Next());
      first_sent = rl::MonoSeconds();
    }
    bus->Handle(5);
  }
  if (probe.inserts.load() == 0) {
    std::fprintf(stderr, "bench_replay: the pixel replay stored nothing\n");
    return false;
  }
  const double first_batch_s = rl::MonoSeconds() - first_sent;

  std::vector<double> rates, mb_rates, offered, loss, cpu_us;
  int64_t sent_total = 0, lost_total = 0;
  const int64_t gaps_before = probe.lost.load();
  const int64_t missing_before = probe.missing_frames.load();
  const int64_t dropped_before = probe.dropped.load();
  double bytes_per_transition = 0;
  for (int r = 0; r < repeats; ++r) {
    const int64_t before = probe.inserts.load();
    const double cpu_before = probe.cpu_seconds.load();
    int64_t sent = 0;
    double bytes = 0;
    const double start = rl::MonoSeconds();
    while (rl::MonoSeconds() - start < seconds) {
      rlmsg::transition_batch_t* m = sim.Next();
      bus->Publish(rl::channels::kTransitions, m);
      sent += m->count;
      bytes += m->getEncodedSize();
      bus->Handle(0);
    }
    const double send_end = rl::MonoSeconds();
    double settled = 0;
    const int64_t stored = Settle(bus, probe, before + sent, 0.3, &settled) - before;
    const double elapsed = settled - start;  // until the last insert was seen
    bytes_per_transition = bytes / static_cast<double>(sent);
    rates.push_back(static_cast<double>(stored) / elapsed);
    mb_rates.push_back(rates.back() * bytes_per_transition / 1e6);
    offered.push_back(static_cast<double>(sent) / (send_end - start));
    loss.push_back(static_cast<double>(sent - stored) / static_cast<double>(sent));
    cpu_us.push_back((probe.cpu_seconds.load() - cpu_before) * 1e6 /
                     static_cast<double>(std::max<int64_t>(1, stored)));
    sent_total += sent;
    lost_total += sent - stored;
  }
  const auto mb = rl::bench::Summarize(mb_rates);
  const auto loss_s = rl::bench::Summarize(loss);
  char extra[768];
  std::snprintf(
      extra, sizeof(extra),
      "\"batch\": %d, \"frame\": \"%dx%d\", \"stack\": %d, \"transport\": \"udpm\", "
      "\"mb_per_s_median\": %.1f, \"mb_per_s_min\": %.1f, \"mb_per_s_max\": %.1f, "
      "\"lcm_bytes_per_transition\": %.0f, \"published_per_s_median\": %.0f, "
      "\"lost_fraction_median\": %.4f, \"lost_fraction_max\": %.4f, \"sent\": %lld, "
      "\"lost\": %lld, \"lost_batches_seq_gaps\": %lld, \"transitions_missing_frames\": %lld, "
      "\"dropped_invalid\": %lld, \"first_batch_s\": %.3f, \"capacity\": %lld, "
      "\"replay_cpu_us_per_transition_median\": %.2f, \"mac\": \"%s\"",
      kBatch, kHeight, kWidth, kStack, mb.median, mb.min, mb.max, bytes_per_transition,
      rl::bench::Summarize(offered).median, loss_s.median, loss_s.max,
      static_cast<long long>(sent_total), static_cast<long long>(lost_total),
      static_cast<long long>(probe.lost.load() - gaps_before),
      static_cast<long long>(probe.missing_frames.load() - missing_before),
      static_cast<long long>(probe.dropped.load() - dropped_before), first_batch_s,
      static_cast<long long>(kCapacity), rl::bench::Summarize(cpu_us).median,
      MacName(bus->config().key));
  rl::bench::Emit(name, "transitions/s", rl::bench::Summarize(rates), repeats, extra);
  return true;
}

// One service of pixel_replay_insert_cpu, keyed or not, and what its windows measured.
struct PixelInsertSide {
  std::string key;
  int port = 0;
  ServiceProbe* probe = nullptr;
  pid_t pid = -1;
  std::vector<double> capacity, cpu_us, thread_cpu_us, lost, mac_share;
};

// The two rows of pixel_replay_insert_cpu (below): the unkeyed service's, then the keyed one's.
void EmitPixelInsertCpu(const PixelInsertSide (&sides)[2], const std::vector<double>& mac_cost,
                        int repeats, double seconds, double rate, bool pin) {
  for (int i = 0; i < 2; ++i) {
    const PixelInsertSide& side = sides[i];
    const auto cpu = rl::bench::Summarize(side.cpu_us);
    const auto lost = rl::bench::Summarize(side.lost);
    char extra[1024];
    int n = std::snprintf(
        extra, sizeof(extra),
        "\"batch\": %d, \"frame\": \"%dx%d\", \"stack\": %d, \"transport\": \"udpm\", "
        "\"offered_transitions_per_s\": %.0f, \"seconds\": %.1f, \"replay\": \"own process\", "
        "\"replay_cpu_us_per_transition_median\": %.3f, \"replay_cpu_us_per_transition_min\": "
        "%.3f, \"replay_cpu_us_per_transition_max\": %.3f, \"lost_fraction_median\": %.4f, "
        "\"lost_fraction_max\": %.4f, \"service_thread_cpu_us_per_transition_median\": %.3f, "
        "\"service_thread_cpu_us_per_transition_min\": %.3f, \"pinned\": %s, \"mac\": \"%s\"",
        kBatch, kHeight, kWidth, kStack, rate, seconds, cpu.median, cpu.min, cpu.max, lost.median,
        lost.max, rl::bench::Summarize(side.thread_cpu_us).median,
        rl::bench::Summarize(side.thread_cpu_us).min, pin ? "true" : "false", MacName(side.key));
    if (i == 1) {
      const auto cost = rl::bench::Summarize(mac_cost);
      const auto share = rl::bench::Summarize(side.mac_share);
      std::snprintf(extra + n, sizeof(extra) - static_cast<size_t>(n),
                    ", \"mac_cost_fraction_median\": %.4f, \"mac_cost_fraction_min\": %.4f, "
                    "\"mac_cost_fraction_max\": %.4f, \"mac_share_of_replay_cpu_median\": %.4f, "
                    "\"mac_share_of_replay_cpu_min\": %.4f, \"mac_share_of_replay_cpu_max\": %.4f",
                    cost.median, cost.min, cost.max, share.median, share.min, share.max);
    }
    rl::bench::Emit(i == 0 ? "pixel_replay_insert_cpu" : "pixel_replay_insert_cpu_mac",
                    "transitions per replay CPU-second", rl::bench::Summarize(side.capacity),
                    repeats, extra);
  }
}

// pixel_replay_insert_cpu, pixel_replay_insert_cpu_mac: what storing a pixel transition costs the
// replay, which is what bounds its insert throughput, without and with the run's key. Two replay
// services, each in a process of its own (forked before this process starts any thread), so that
// a service's CPU time is that of all its threads (LCM's receive threads included) and of nothing
// else; given two or more CPUs, the services run on the last and the actors on the first, so that
// neither takes the other's. One actor per service publishes batches of kBatch transitions paced
// at `rate` transitions/s, a rate both keep up with, and both actors compute a MAC per batch (the
// unkeyed one drops it). The windows alternate between the two services in pairs of either
// order, so that the machine's drift falls on both. value: transitions stored per second of the
// replay's CPU time (its insert capacity on one core); with the CPU time per transition and the
// share lost. The _mac row adds what the key costs the replay, two ways: its bus's time in MAC
// checks over the replay's CPU time in the same window (mac_share_of_replay_cpu), and the capacity
// lost against the unkeyed window of the same pair (mac_cost_fraction, which the machine's noise
// widens).
int PixelInsertCpu(int repeats, double seconds, int port, double rate) {
  // The first and the last of this process's CPUs (given back at the end), for the actors and
  // the services.
  cpu_set_t all_cpus;
  int first_cpu = -1, last_cpu = -1;
  if (sched_getaffinity(0, sizeof(all_cpus), &all_cpus) == 0) {
    for (int c = 0; c < CPU_SETSIZE; ++c) {
      if (!CPU_ISSET(c, &all_cpus)) continue;
      if (first_cpu < 0) first_cpu = c;
      last_cpu = c;
    }
  }
  const bool pin = first_cpu >= 0 && last_cpu > first_cpu;
  // The unkeyed side's actor computes a MAC too (over its batch's frames, nearly all of its
  // bytes) and drops it, so that the actor's load on the machine is the same on both sides.
  LooseGmac unkeyed_signer;
  int64_t unkeyed_seq = 0;
  PixelInsertSide sides[2];
  sides[0].port = port;
  sides[1].key = std::string(rl::kKeyBytes, 'k');
  sides[1].port = port + 3;  // each bus takes 3 ports (main, bulk, samples)
  auto stop = [&] {
    for (PixelInsertSide& side : sides) {
      if (side.probe == nullptr) continue;
      side.probe->stop = true;
      if (side.pid > 0) waitpid(side.pid, nullptr, 0);
      munmap(side.probe, sizeof(ServiceProbe));
      side.probe = nullptr;
    }
    if (pin) sched_setaffinity(0, sizeof(all_cpus), &all_cpus);
  };
  for (PixelInsertSide& side : sides) {
    void* shared = mmap(nullptr, sizeof(ServiceProbe), PROT_READ | PROT_WRITE,
                        MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared == MAP_FAILED) {
      std::perror("bench_replay: mmap");
      stop();
      return 1;
    }
    side.probe = new (shared) ServiceProbe();
    side.pid = fork();
    if (side.pid < 0) {
      std::perror("bench_replay: fork");
      stop();
      return 1;
    }
    if (side.pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (pin) PinTo(last_cpu);
      RunPixelService(side.port, side.probe, side.key);
      _exit(0);
    }
  }

  if (pin) PinTo(first_cpu);
  std::vector<std::unique_ptr<rl::Bus>> buses;
  std::vector<std::unique_ptr<PixelActorSim>> sims;
  for (int i = 0; i < 2; ++i) {
    buses.push_back(std::make_unique<rl::Bus>(Config(sides[i].port, "actor-0", sides[i].key)));
    sims.push_back(std::make_unique<PixelActorSim>(0, 1));
    if (!WaitForReplay(buses[i].get())) {
      std::fprintf(stderr, "bench_replay: a forked pixel replay service did not come up\n");
      stop();
      return 1;
    }
    // The first batch makes the service allocate its table.
    const double first = rl::MonoSeconds();
    while (sides[i].probe->inserts.load() == 0 && rl::MonoSeconds() - first < 10) {
      buses[i]->Publish(rl::channels::kTransitions, sims[i]->Next());
      double settled = 0;
      Settle(buses[i].get(), *sides[i].probe, 1, 2.0, &settled);
    }
  }

  std::vector<double> mac_cost;
  for (int r = 0; r < repeats; ++r) {
    // The pairs' order alternates (unkeyed first, then keyed first): a window measures slower
    // after the other side's than before it (a few %, on this machine with no key on either side).
    for (int k = 0; k < 2; ++k) {
      const int i = r % 2 == 0 ? k : 1 - k;
      PixelInsertSide& side = sides[i];
      rl::Bus* bus = buses[i].get();
      const int64_t before = side.probe->inserts.load();
      const double cpu_before = side.probe->process_cpu_seconds.load();
      const double thread_before = side.probe->cpu_seconds.load();
      const int64_t mac_before = side.probe->mac_nanos.load();
      int64_t sent = 0;
      const double start = rl::MonoSeconds();
      double next = start;
      while (rl::MonoSeconds() - start < seconds) {
        rlmsg::transition_batch_t* m = sims[i]->Next();
        bus->Publish(rl::channels::kTransitions, m);
        if (i == 0) {
          unsigned char tag[16];
          unkeyed_signer.Tag(++unkeyed_seq, m->frames.data(), m->frames.size(), tag);
        }
        sent += m->count;
        next += kBatch / rate;
        bus->Handle(0);
        while (rl::MonoSeconds() < next) std::this_thread::sleep_for(std::chrono::microseconds(50));
      }
      double settled = 0;
      const int64_t stored = Settle(bus, *side.probe, before + sent, 0.3, &settled) - before;
      const double cpu = side.probe->process_cpu_seconds.load() - cpu_before;
      side.capacity.push_back(static_cast<double>(stored) / std::max(cpu, 1e-9));
      side.cpu_us.push_back(cpu * 1e6 / static_cast<double>(std::max<int64_t>(1, stored)));
      side.thread_cpu_us.push_back((side.probe->cpu_seconds.load() - thread_before) * 1e6 /
                                   static_cast<double>(std::max<int64_t>(1, stored)));
      side.lost.push_back(static_cast<double>(sent - stored) / static_cast<double>(sent));
      side.mac_share.push_back(static_cast<double>(side.probe->mac_nanos.load() - mac_before) *
                               1e-9 / std::max(cpu, 1e-9));
    }
    mac_cost.push_back(1.0 - sides[1].capacity.back() / sides[0].capacity.back());
  }
  stop();

  EmitPixelInsertCpu(sides, mac_cost, repeats, seconds, rate, pin);
  return 0;
}

// pixel_replay_sample: kSampleInFlight requests of kBatch stacks outstanding, as the learner
// keeps them; a request without a reply after 0.5 s is given up and replaced.
void PixelSample(rl::Bus* bus, int repeats, double seconds) {
  // Shared with the handler, which stays subscribed after this function returns.
  struct State {
    std::map<int64_t, double> outstanding;  // request id -> when sent
    int64_t received = 0, batches = 0;
  };
  auto state = std::make_shared<State>();
  State& st = *state;
  const std::string me = bus->config().sender;
  bus->Subscribe<rlmsg::sample_batch_t>(
      rl::channels::kSamples,
      [state, me](const rlmsg::sample_batch_t& m) {
        if (m.requester != me || state->outstanding.erase(m.request_id) == 0) return;
        state->received += m.count;
        ++state->batches;
      },
      rl::Port::kSamples);
  int64_t next_id = 0, timeouts = 0;
  const int64_t gaps_before = bus->counters().lost;
  std::vector<double> rates, batch_rates;
  for (int r = 0; r < repeats; ++r) {
    const int64_t before = st.received, batches_before = st.batches;
    const double start = rl::MonoSeconds();
    double now = start;
    while (now - start < seconds) {
      for (auto it = st.outstanding.begin(); it != st.outstanding.end();) {
        if (now - it->second > 0.5) {
          it = st.outstanding.erase(it);
          ++timeouts;
        } else {
          ++it;
        }
      }
      while (static_cast<int>(st.outstanding.size()) < kSampleInFlight) {
        rlmsg::sample_request_t req{};
        req.request_id = next_id++;
        req.batch_size = kBatch;
        bus->Publish(rl::channels::kSampleRequest, &req);
        st.outstanding[req.request_id] = now;
      }
      bus->Handle(1);
      now = rl::MonoSeconds();
    }
    const double elapsed = now - start;
    rates.push_back(static_cast<double>(st.received - before) / elapsed);
    batch_rates.push_back(static_cast<double>(st.batches - batches_before) / elapsed);
  }
  const auto b = rl::bench::Summarize(batch_rates);
  const double reply_mb = 2.0 * kBatch * kStack * kFrameBytes / 1e6;
  char extra[512];
  std::snprintf(extra, sizeof(extra),
                "\"batch\": %d, \"frame\": \"%dx%d\", \"stack\": %d, \"in_flight\": %d, "
                "\"transport\": \"udpm\", \"port\": \"samples\", \"batches_per_s_median\": %.1f, "
                "\"batches_per_s_min\": %.1f, \"batches_per_s_max\": %.1f, \"reply_mb\": %.2f, "
                "\"mb_per_s_median\": %.0f, \"replies_timed_out\": %lld, "
                "\"replies_lost_seq_gaps\": %lld",
                kBatch, kHeight, kWidth, kStack, kSampleInFlight, b.median, b.min, b.max, reply_mb,
                b.median * reply_mb, static_cast<long long>(timeouts),
                static_cast<long long>(bus->counters().lost - gaps_before));
  rl::bench::Emit("pixel_replay_sample", "transitions/s", rl::bench::Summarize(rates), repeats,
                  extra);
}

// pixel_replay_8_actors[_<m>x]: kActors actor threads, each with its own bus (subscribed to
// RL_FLOW and handling it between batches, as actor/actor.cc does), publishing one batch every
// kBatch / (kStepsPerActor * multiplier) seconds from a random phase. The delivered rate is
// measured over `windows` windows of `seconds` once every actor has started; the loss over the
// whole run, after the service has settled.
void PixelActors(rl::Bus* bus, const ServiceProbe& probe, int port, int multiplier, int windows,
                 double seconds, int32_t first_actor_id) {
  const double rate = kStepsPerActor * multiplier;  // transitions/s of one actor
  const double period = kBatch / rate;
  std::atomic<int64_t> sent{0};
  std::atomic<int64_t> sent_bytes{0};
  std::atomic<int64_t> publish_failures{0};
  std::atomic<int64_t> flow_messages{0};
  const int64_t before = probe.inserts.load();
  const int64_t gaps_before = probe.lost.load();
  const int64_t missing_before = probe.missing_frames.load();
  const int64_t dropped_before = probe.dropped.load();
  // Each actor starts within one period after t0; the windows start once all have.
  const double t0 = rl::MonoSeconds() + 0.5;  // time for the threads to open their sockets
  const double t_start = t0 + period;
  const double t_end = t_start + windows * seconds;
  std::vector<std::thread> actors;
  for (int a = 0; a < kActors; ++a) {
    const int32_t id = first_actor_id + a;
    actors.emplace_back([&, id] {
      rl::Bus actor_bus(Config(port, "actor-" + std::to_string(id), bus->config().key));
      actor_bus.Subscribe<rlmsg::flow_control_t>(
          rl::channels::kFlow, [&](const rlmsg::flow_control_t&) { ++flow_messages; });
      PixelActorSim sim(id, 1000 + static_cast<uint64_t>(id));
      std::mt19937_64 rng(static_cast<uint64_t>(id));
      const double phase = std::uniform_real_distribution<double>(0, period)(rng);
      for (int64_t j = 0;; ++j) {
        const double due = t0 + phase + static_cast<double>(j) * period;
        if (due >= t_end) break;
        rlmsg::transition_batch_t* m = sim.Next();  // the actor's work happens before the due time
        const double wait = due - rl::MonoSeconds();
        if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
        if (!actor_bus.Publish(rl::channels::kTransitions, m)) ++publish_failures;
        sent += m->count;
        sent_bytes += m->getEncodedSize();
        actor_bus.Handle(0);
      }
    });
  }

  // Windows: the learner's bus is handled meanwhile, as a learner process would.
  auto handle_until = [&](double t) {
    for (double now = rl::MonoSeconds(); now < t; now = rl::MonoSeconds()) {
      bus->Handle(std::max(1, std::min(20, static_cast<int>((t - now) * 1000))));
    }
  };
  handle_until(t_start);
  std::vector<double> delivered;
  int64_t mark = probe.inserts.load();
  for (int w = 0; w < windows; ++w) {
    handle_until(t_start + (w + 1) * seconds);
    const int64_t now_count = probe.inserts.load();
    delivered.push_back(static_cast<double>(now_count - mark) / seconds);
    mark = now_count;
  }
  for (std::thread& t : actors) t.join();
  double settled = 0;
  const int64_t stored = Settle(bus, probe, before + sent.load(), 0.5, &settled) - before;
  const int64_t lost = sent.load() - stored;

  char name[64];
  if (multiplier == 1) {
    std::snprintf(name, sizeof(name), "pixel_replay_8_actors");
  } else {
    std::snprintf(name, sizeof(name), "pixel_replay_8_actors_%dx%s", multiplier,
                  bus->config().key.empty() ? "" : "_mac");
  }
  const double offered = rate * kActors;
  char extra[1024];
  std::snprintf(
      extra, sizeof(extra),
      "\"actors\": %d, \"steps_per_actor_per_s\": %.0f, \"rate_multiplier\": %d, "
      "\"offered_transitions_per_s\": %.0f, \"offered_mb_per_s\": %.2f, \"batch\": %d, "
      "\"frame\": \"%dx%d\", \"stack\": %d, \"transport\": \"udpm\", \"seconds\": %.1f, "
      "\"sent\": %lld, \"stored\": %lld, \"lost_transitions\": %lld, \"zero_loss\": %s, "
      "\"lost_batches_seq_gaps\": %lld, \"transitions_missing_frames\": %lld, "
      "\"dropped_invalid\": %lld, \"publish_failures\": %lld, \"flow_messages_seen\": %lld, "
      "\"samples_per_insert\": 0",
      kActors, kStepsPerActor, multiplier, offered,
      offered * static_cast<double>(sent_bytes.load()) /
          static_cast<double>(std::max<int64_t>(1, sent.load())) / 1e6,
      kBatch, kHeight, kWidth, kStack, t_end - t0, static_cast<long long>(sent.load()),
      static_cast<long long>(stored), static_cast<long long>(lost), lost == 0 ? "true" : "false",
      static_cast<long long>(probe.lost.load() - gaps_before),
      static_cast<long long>(probe.missing_frames.load() - missing_before),
      static_cast<long long>(probe.dropped.load() - dropped_before),
      static_cast<long long>(publish_failures.load()),
      static_cast<long long>(flow_messages.load()));
  rl::bench::Emit(name, "transitions/s", rl::bench::Summarize(delivered), windows, extra);
}

// Pixel benchmarks through LCM, on `port` to port + 2; with a key, or insert_only, only the
// insert row.
int RunPixelLcm(int repeats, double seconds, int port, const std::string& key = "",
                bool insert_only = false) {
  ServiceProbe probe;
  std::thread service_thread([&] { RunPixelService(port, &probe, key); });
  auto stop = [&] {
    probe.stop = true;
    service_thread.join();
  };

  rl::Bus bus(Config(port, "learner", key));
  if (!WaitForReplay(&bus)) {
    std::fprintf(stderr, "bench_replay: the pixel replay service did not come up\n");
    stop();
    return 1;
  }
  if (!PixelInsert(&bus, probe, repeats, seconds,
                   key.empty() ? "pixel_replay_insert" : "pixel_replay_insert_mac")) {
    stop();
    return 1;
  }
  if (!key.empty()) PixelActors(&bus, probe, port, 4, std::max(repeats, 3), seconds, 300);
  if (!key.empty() || insert_only) {
    stop();
    return 0;
  }
  PixelSample(&bus, repeats, seconds);
  const int windows = std::max(repeats, 3);
  PixelActors(&bus, probe, port, 1, windows, seconds, 100);
  PixelActors(&bus, probe, port, 4, windows, seconds, 200);
  stop();
  return 0;
}

// The first line of the /proc file `path` that starts with `field` (e.g. "VmRSS:"), its number
// of kB in bytes; 0 when the file or the line cannot be read.
int64_t ProcKbField(const char* path, const char* field) {
  std::FILE* f = std::fopen(path, "r");
  if (f == nullptr) return 0;
  const size_t length = std::strlen(field);
  char line[256];
  int64_t kb = 0;
  while (std::fgets(line, sizeof(line), f) != nullptr) {
    if (std::strncmp(line, field, length) == 0) {
      kb = std::atoll(line + length);
      break;
    }
  }
  std::fclose(f);
  return kb * 1024;
}

// VmRSS of this process in bytes (0 when it cannot be read).
int64_t RssBytes() { return ProcKbField("/proc/self/status", "VmRSS:"); }

// pixel_replay_bytes_per_transition[_prioritized]: a PixelTable of kMemoryFill transitions, its
// own accounting and the process's RSS growth.
void PixelMemory(bool prioritized) {
  // Actors first (their message buffers are not the table's), then a clean baseline.
  std::vector<PixelActorSim> sims;
  std::vector<rlmsg::transition_batch_t*> next;
  sims.reserve(kActors);
  for (int a = 0; a < kActors; ++a) {
    sims.emplace_back(a, 500 + static_cast<uint64_t>(a));
  }
  for (PixelActorSim& s : sims) next.push_back(s.Next());
  malloc_trim(0);
  const int64_t rss_before = RssBytes();
  const double start = rl::MonoSeconds();

  rl::replay::PixelTableOptions o;
  o.capacity = kMemoryFill;
  o.height = kHeight;
  o.width = kWidth;
  o.stack = kStack;
  std::unique_ptr<rl::replay::Sampler> sampler;
  if (prioritized) {
    sampler = std::make_unique<rl::replay::PrioritizedSampler>(kMemoryFill, 0.6, 1e-6);
  } else {
    sampler = std::make_unique<rl::replay::UniformSampler>(kMemoryFill);
  }
  rl::replay::PixelTable table(o, std::move(sampler));
  const double alloc_s = rl::MonoSeconds() - start;
  while (table.total_inserts() < kMemoryFill) {
    for (size_t a = 0; a < sims.size() && table.total_inserts() < kMemoryFill; ++a) {
      const char* why = table.Insert(rl::replay::ViewOf(*next[a]));
      RL_CHECK(why == nullptr) << why;
      next[a] = sims[a].Next();
    }
  }
  const double fill_s = rl::MonoSeconds() - start;
  const int64_t rss_growth = RssBytes() - rss_before;
  RL_CHECK(table.transitions_missing_frames() == 0) << "the simulated actors lost frames";

  const double size = static_cast<double>(table.size());
  const double per = static_cast<double>(table.memory_bytes()) / size;
  const double rss_per = static_cast<double>(rss_growth) / size;
  char extra[768];
  std::snprintf(
      extra, sizeof(extra),
      "\"sampler\": \"%s\", \"frame\": \"%dx%d\", \"stack\": %d, \"size\": %lld, "
      "\"frame_capacity\": %lld, \"memory_bytes\": %lld, \"frames_per_transition\": %.4f, "
      "\"gb_at_1m_transitions\": %.2f, \"rss_growth_bytes\": %lld, "
      "\"rss_bytes_per_transition\": %.0f, \"rss_frames_per_transition\": %.4f, "
      "\"rss_gb_at_1m_transitions\": %.2f, \"stacked_bytes_per_transition\": %d, "
      "\"actors\": %d, \"episode_steps\": \"%d-%d\", \"alloc_s\": %.2f, \"fill_s\": %.2f",
      prioritized ? "prioritized" : "uniform", kHeight, kWidth, kStack,
      static_cast<long long>(table.size()), static_cast<long long>(table.frame_capacity()),
      static_cast<long long>(table.memory_bytes()), per / kFrameBytes, per * 1e6 / 1e9,
      static_cast<long long>(rss_growth), rss_per, rss_per / kFrameBytes, rss_per * 1e6 / 1e9,
      2 * kStack * kFrameBytes, kActors, kMinEpisode, kMaxEpisode, alloc_s, fill_s);
  rl::bench::Summary s;
  s.min = s.median = s.max = per;
  rl::bench::Emit(prioritized ? "pixel_replay_bytes_per_transition_prioritized"
                              : "pixel_replay_bytes_per_transition",
                  "bytes/transition", s, 1, extra);
}

// Bytes of this process's anonymous memory in transparent huge pages (0 when unknown).
int64_t AnonHugePageBytes() { return ProcKbField("/proc/self/smaps_rollup", "AnonHugePages:"); }

// Snapshots of a full table: `insert` stores one batch and returns its transitions, `save` adds
// the table to a snapshot. Emits the pause and write rows for `name`.
void SnapshotRows(const std::string& name, int repeats, const std::function<int()>& insert,
                  const std::function<std::string(rl::StateStream*)>& save) {
  namespace fs = std::filesystem;
  const std::string path =
      (fs::temp_directory_path() / ("bench_replay_snapshot_" + std::to_string(getpid()) + ".bin"))
          .string();
  rl::replay::SnapshotterOptions options;
  options.path = path;
  options.every_seconds = 1e9;  // only StartNow()
  options.program = "bench_replay";
  int64_t version = 0;
  rl::replay::Snapshotter snapshots(options, rl::replay::ReplayService::kSnapshotKind, save,
                                    [&version] { return version; });
  std::vector<double> pauses, forks, writes, rates_during, rates_before;
  int64_t bytes = 0;
  for (int r = 0; r < repeats; ++r) {
    // The insert rate without a snapshot, for as long as the last write took (at least 0.2 s).
    const double window = std::max(0.2, writes.empty() ? 0.5 : writes.back());
    int64_t inserted = 0;
    double start = rl::MonoSeconds();
    while (rl::MonoSeconds() - start < window) inserted += insert();
    rates_before.push_back(static_cast<double>(inserted) / (rl::MonoSeconds() - start));
    // A snapshot, inserting on while the child writes.
    ++version;
    RL_CHECK(snapshots.StartNow()) << "snapshot not started";
    inserted = 0;
    start = rl::MonoSeconds();
    while (snapshots.running()) {
      inserted += insert();
      snapshots.Tick(rl::MonoSeconds());
    }
    rates_during.push_back(static_cast<double>(inserted) / (rl::MonoSeconds() - start));
    const rl::replay::SnapshotStats& st = snapshots.stats();
    RL_CHECK(st.failed == 0) << "a snapshot failed";
    pauses.push_back(1e3 * st.last_pause_seconds);
    forks.push_back(1e3 * st.last_fork_seconds);
    writes.push_back(st.last_write_seconds);
    bytes = st.last_bytes;
  }
  fs::remove(path);
  const rl::bench::Summary fork = rl::bench::Summarize(forks);
  char extra[512];
  std::snprintf(extra, sizeof(extra),
                "\"bytes\": %lld, \"rss_bytes\": %lld, \"anon_huge_page_bytes\": %lld, "
                "\"fork_ms_median\": %.3f, \"fork_ms_max\": %.3f",
                static_cast<long long>(bytes), static_cast<long long>(RssBytes()),
                static_cast<long long>(AnonHugePageBytes()), fork.median, fork.max);
  rl::bench::Emit("replay_snapshot_pause_" + name, "ms", rl::bench::Summarize(pauses), repeats,
                  extra);
  const rl::bench::Summary during = rl::bench::Summarize(rates_during);
  const rl::bench::Summary before = rl::bench::Summarize(rates_before);
  std::snprintf(extra, sizeof(extra),
                "\"bytes\": %lld, \"mb_per_s_median\": %.0f, "
                "\"inserts_per_s_during_write_median\": %.0f, "
                "\"inserts_per_s_without_median\": %.0f",
                static_cast<long long>(bytes),
                static_cast<double>(bytes) / 1e6 / rl::bench::Summarize(writes).median,
                during.median, before.median);
  rl::bench::Emit("replay_snapshot_write_" + name, "s", rl::bench::Summarize(writes), repeats,
                  extra);
}

// replay_snapshot_*_pixel: a full CarRacing-size prioritized pixel table.
void PixelSnapshots(int repeats) {
  rl::replay::PixelTableOptions o;
  o.capacity = kCapacity;
  o.frame_capacity = 130'000;
  o.height = kHeight;
  o.width = kWidth;
  o.stack = kStack;
  rl::replay::PixelTable table(
      o, std::make_unique<rl::replay::PrioritizedSampler>(kCapacity, 0.6, 1e-6));
  std::vector<PixelActorSim> sims;
  for (int a = 0; a < kActors; ++a) sims.emplace_back(a, 900 + static_cast<uint64_t>(a));
  size_t turn = 0;
  const auto insert = [&] {
    const char* why = table.Insert(rl::replay::ViewOf(*sims[turn++ % sims.size()].Next()));
    RL_CHECK(why == nullptr) << why;
    return kBatch;
  };
  // Every frame and slot written once.
  while (table.total_frames() < o.frame_capacity || table.total_inserts() < kCapacity) insert();
  SnapshotRows("pixel", repeats, insert, [&table](rl::StateStream* out) {
    table.Save("pixels.", out);
    return std::string("pixel table");
  });
}

// replay_snapshot_*_flat: a full CartPole-size uniform flat table.
void FlatSnapshots(int repeats) {
  rl::replay::ReplayTableOptions o;
  o.capacity = 50'000;
  o.obs_size = 4;
  o.action_width = 1;
  rl::replay::ReplayTable table(o);
  std::vector<float> obs(kBatch * 4, 0.5f), action(kBatch, 1.0f), reward(kBatch, 1.0f),
      discount(kBatch, 0.99f);
  rl::replay::TransitionBatchView batch;
  batch.obs_size = 4;
  batch.count = kBatch;
  batch.obs = batch.next_obs = obs;
  batch.columns = rl::replay::ColumnsView{1, action, reward, discount, {}, {}};
  const auto insert = [&] {
    const char* why = table.Insert(batch);
    RL_CHECK(why == nullptr) << why;
    return kBatch;
  };
  while (table.total_inserts() < o.capacity) insert();
  SnapshotRows("flat", repeats, insert, [&table](rl::StateStream* out) {
    table.Save("flat.", out);
    return std::string("flat table");
  });
}

}  // namespace

// mac_aes256_gmac: checking (common/message_auth.h: OpenSSL's AES-256-GCM as GMAC) messages of a
// pixel batch's size (32 transitions with their frames) and of a sample reply's (4 MB), MB/s; for
// comparison, over the same bytes, mac_hmac_sha256: HMAC-SHA256 (OpenSSL), the MAC used before
// GMAC.
void MacRows(int repeats) {
  rl::MessageAuthenticator auth(std::string(rl::kKeyBytes, 'k'));
  const std::string key(rl::kKeyBytes, 'k');
  const std::string sender = "actor-1";
  const size_t at = rl::MacOffset(sender.size());
  for (const size_t size : {size_t{230'000}, size_t{4'000'000}}) {
    // Header bytes as MacOffset() lays them out: the sender's length and name, MAC zero.
    std::vector<uint8_t> msg(size, 0x5a);
    msg[16] = msg[17] = msg[18] = 0;
    msg[19] = static_cast<uint8_t>(sender.size() + 1);
    std::copy(sender.begin(), sender.end(), msg.begin() + 20);
    msg[20 + sender.size()] = 0;
    std::fill(msg.begin() + static_cast<std::ptrdiff_t>(at),
              msg.begin() + static_cast<std::ptrdiff_t>(at + rl::kMacBytes), 0);
    if (!auth.Sign("RL_TRANSITIONS", msg.data(), msg.size(), at)) std::abort();
    for (const bool gmac : {true, false}) {
      std::vector<double> rates;
      for (int r = 0; r < repeats; ++r) {
        int64_t n = 0;
        const double start = rl::MonoSeconds();
        while (rl::MonoSeconds() - start < 0.3) {
          unsigned char md[32];
          unsigned int md_size = 0;
          if (gmac ? auth.Verify("RL_TRANSITIONS", msg.data(), msg.size(), at) != nullptr
                   : HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), msg.data(),
                          msg.size(), md, &md_size) == nullptr) {
            std::abort();
          }
          ++n;
        }
        rates.push_back(static_cast<double>(n) * static_cast<double>(size) / 1e6 /
                        (rl::MonoSeconds() - start));
      }
      char extra[96];
      std::snprintf(extra, sizeof(extra), "\"message_bytes\": %zu, \"mac_bytes\": %zu", size,
                    rl::kMacBytes);
      const std::string name = std::string(gmac ? "mac_aes256_gmac_" : "mac_hmac_sha256_") +
                               (size < 1'000'000 ? "pixel_batch" : "4mb");
      rl::bench::Emit(name, "MB/s", rl::bench::Summarize(rates), repeats, extra);
    }
  }
}

// bus_receive_real_*, bus_drop_forged_*: see the top of the file. Each repeat delivers `count`
// real messages (a new incarnation each repeat, so none is replayed) and as many forged ones.
void BusReceiveRows(int repeats) {
  const std::string key(rl::kKeyBytes, 'k');
  rl::MessageAuthenticator signer(key);
  for (const bool pixels : {false, true}) {
    rl::BusConfig config = rl::InProcessBusConfig(77, "replay");
    config.key = key;
    rl::Bus bus(config);
    int64_t handled = 0;
    bus.Subscribe<rlmsg::transition_batch_t>(
        rl::channels::kTransitions, [&handled](const rlmsg::transition_batch_t&) { ++handled; });
    PixelActorSim sim(0, 1);
    rlmsg::transition_batch_t m = pixels ? *sim.Next() : rl::bench::FlatBatch();
    m.header.run_id = 77;
    m.header.sender = "actor-0";
    const size_t at = rl::MacOffset(m.header.sender.size());
    const int count = pixels ? 128 : 20'000;
    std::vector<std::vector<uint8_t>> real(static_cast<size_t>(count)), forged(real.size());
    std::vector<double> real_us, forged_us, ratio;
    int64_t incarnation = rl::WallMicros() - 1'000'000;
    for (int r = 0; r < repeats; ++r) {
      const int64_t now = rl::WallMicros();
      ++incarnation;
      for (int i = 0; i < count; ++i) {
        std::vector<uint8_t>& bytes = real[static_cast<size_t>(i)];
        m.header.incarnation = incarnation;
        m.header.seq = i;
        m.header.utime = now;
        bytes.resize(static_cast<size_t>(m.getEncodedSize()));
        if (m.encode(bytes.data(), 0, static_cast<int>(bytes.size())) !=
                static_cast<int>(bytes.size()) ||
            !signer.Sign(rl::channels::kTransitions, bytes.data(), bytes.size(), at)) {
          std::abort();
        }
        // A forger's: a sender name and an incarnation of its own, a MAC it had to guess.
        std::vector<uint8_t>& f = forged[static_cast<size_t>(i)];
        f = bytes;
        char name[8];
        std::snprintf(name, sizeof(name), "f%06d", i % 1'000'000);
        std::memcpy(f.data() + 20, name, 7);
        f[at - 1] ^= static_cast<uint8_t>(i);
        f[at - 2] ^= static_cast<uint8_t>(i >> 8);
        f[at] ^= 1;
      }
      const int64_t handled_before = handled;
      double start = rl::MonoSeconds();
      for (const auto& bytes : real) {
        bus.Deliver(rl::channels::kTransitions, bytes.data(), bytes.size(), now);
      }
      real_us.push_back((rl::MonoSeconds() - start) * 1e6 / count);
      const int64_t refused_before = bus.counters().unauthenticated;
      start = rl::MonoSeconds();
      for (const auto& bytes : forged) {
        bus.Deliver(rl::channels::kTransitions, bytes.data(), bytes.size(), now);
      }
      forged_us.push_back((rl::MonoSeconds() - start) * 1e6 / count);
      ratio.push_back(forged_us.back() / real_us.back());
      if (handled - handled_before != count ||
          bus.counters().unauthenticated - refused_before != count) {
        std::fprintf(stderr, "bench_replay: the bus took a forged message or refused a real one\n");
        std::abort();
      }
    }
    const std::string kind = pixels ? "pixel" : "flat";
    char extra[256];
    std::snprintf(extra, sizeof(extra), "\"message_bytes\": %zu, \"messages\": %d, \"mac\": \"%s\"",
                  real[0].size(), count, MacName(key));
    rl::bench::Emit("bus_receive_real_" + kind, "us/message", rl::bench::Summarize(real_us),
                    repeats, extra);
    const auto r = rl::bench::Summarize(ratio);
    std::snprintf(extra, sizeof(extra),
                  "\"message_bytes\": %zu, \"messages\": %d, \"mac\": \"%s\", "
                  "\"forged_over_real_median\": %.3f, \"forged_over_real_min\": %.3f, "
                  "\"forged_over_real_max\": %.3f",
                  real[0].size(), count, MacName(key), r.median, r.min, r.max);
    rl::bench::Emit("bus_drop_forged_" + kind, "us/message", rl::bench::Summarize(forged_us),
                    repeats, extra);
  }
}

// pixel_replay_insert_cpu's paced rate: a third of what one actor publishing back to back gets
// stored (pixel_replay_insert), so that the replay keeps up and none of its CPU goes to losses.
constexpr double kInsertCpuRate = 100'000;

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  const bool has_mode = mode == "--mac" || mode == "--snapshots";
  const rl::bench::Args args(
      argc, argv,
      "usage: bench_replay [REPEATS (5)] [SECONDS per repeat (1)] [PORT (17667; up to PORT+7)]\n"
      "       bench_replay --mac [REPEATS] [SECONDS] [PORT]\n"
      "       bench_replay --snapshots [REPEATS]\n"
      "The replay through LCM, its memory, the MAC's cost (--mac) or the snapshots' "
      "(--snapshots) (JSON lines).",
      mode == "--snapshots" ? 1 : 3, has_mode ? 2 : 1);
  const int repeats = args.Int(0, 5);
  if (mode == "--mac") {
    // The MAC's cost alone: its throughput, and pixel inserts without and with it.
    const double seconds = args.Number(1, 1.0);
    const int port = args.Int(2, 17667);
    // Forks its replay processes, so it runs first, while this process has no other thread.
    if (const int rc = PixelInsertCpu(repeats, 2 * seconds, port + 9, kInsertCpuRate); rc != 0) {
      return rc;
    }
    MacRows(repeats);
    BusReceiveRows(repeats);
    if (const int rc = RunPixelLcm(repeats, seconds, port + 3, "", /*insert_only=*/true); rc != 0) {
      return rc;
    }
    return RunPixelLcm(repeats, seconds, port + 6, std::string(rl::kKeyBytes, 'k'));
  }
  if (mode == "--snapshots") {
    FlatSnapshots(repeats);
    PixelSnapshots(repeats);
    return 0;
  }
  const double seconds = args.Number(1, 1.0);
  const int port = args.Int(2, 17667);

  // Forks its replay processes, so it runs first, while this process has no other thread.
  if (const int rc = PixelInsertCpu(repeats, 2 * seconds, port + 9, kInsertCpuRate); rc != 0) {
    return rc;
  }
  if (const int rc = RunFlat(repeats, seconds, port); rc != 0) return rc;
  if (const int rc = RunPixelLcm(repeats, seconds, port + 3); rc != 0) return rc;
  MacRows(repeats);
  BusReceiveRows(repeats);
  if (const int rc = RunPixelLcm(repeats, seconds, port + 6, std::string(rl::kKeyBytes, 'k'));
      rc != 0) {
    return rc;
  }
  PixelMemory(/*prioritized=*/false);
  PixelMemory(/*prioritized=*/true);
  FlatSnapshots(repeats);
  PixelSnapshots(repeats);
  return 0;
}
