// Writes the generated seed corpora of the fuzz targets: valid messages of every type
// (fuzz_messages), learner state files (fuzz_state_file) and policy checkpoints
// (fuzz_checkpoint), inputs of the handler targets (weights chunks, sample replies, transition
// batches, checkpoint announcements), made with the project's own encoders and writers, so that
// they follow the current formats. Run by `scripts/fuzz.sh --seeds` after a change to lcmtypes/ or
// to a file format. Every message written is checked to decode and validate.
//
// Usage: fuzz_seeds CORPUS_DIR   (rewrites CORPUS_DIR/{messages,state_file,checkpoint,snapshot,
// weights,batch_decoder,replay_insert,announced_checkpoint}/, keeping the reproducers of fixed
// bugs, named "repro-*")
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/message_examples.h"
#include "common/messages.h"
#include "envs/specs.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/handler_setup.h"
#include "fuzz/learner_state.h"
#include "learner/td3.h"
#include "learner/weights_publisher.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"
#ifdef RL_FUZZ_SNAPSHOT
#include "fuzz/replay_setup.h"
#endif

namespace {

namespace fs = std::filesystem;

void WriteFile(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "fuzz_seeds: cannot write %s\n", path.c_str());
    std::exit(1);
  }
}

// ---- Messages ----

// Writes `msg` as "<dir>/<type>-<variant>": its type index (common/channels.h), then its encoding.
template <class Msg>
void WriteMessage(const fs::path& dir, const Msg& msg, const std::string& variant) {
  const int size = msg.getEncodedSize();
  std::string bytes(static_cast<size_t>(size) + 1, '\0');
  bytes[0] = static_cast<char>(rl::MessageIndex(Msg::getTypeName()));
  if (msg.encode(bytes.data() + 1, 0, size) != size) {
    std::fprintf(stderr, "fuzz_seeds: %s does not encode\n", Msg::getTypeName());
    std::exit(1);
  }
  Msg decoded{};
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data() + 1);
  const char* why = rl::Decode(data, static_cast<size_t>(size), &decoded);
  if (why == nullptr) why = rl::Validate(decoded);
  if (why != nullptr) {
    std::fprintf(stderr, "fuzz_seeds: %s %s is refused: %s\n", Msg::getTypeName(), variant.c_str(),
                 why);
    std::exit(1);
  }
  std::string name = Msg::getTypeName();
  if (name.rfind("rlmsg.", 0) == 0) name = name.substr(6);
  WriteFile(dir / (name + "-" + variant), bytes);
}

// The example of every type (common/message_examples.h), and the other kind of each batch.
void WriteMessages(const fs::path& dir) {
#define RL_WRITE_EXAMPLE(type, constant, name, port) \
  WriteMessage(dir, rl::examples::Example<rlmsg::type>(), "a");
  RL_MESSAGES(RL_WRITE_EXAMPLE)
#undef RL_WRITE_EXAMPLE
  rlmsg::flow_control_t flow = rl::examples::Example<rlmsg::flow_control_t>();
  flow.num_actors = 0;
  flow.actor_id.clear();
  flow.actor_inserts.clear();
  flow.insert_credit = -1;
  WriteMessage(dir, flow, "no-actors");
  WriteMessage(dir, rl::examples::PixelSamples(1, 4, 3, 2, 3), "pixels");
  WriteMessage(dir, rl::examples::PixelTransitions(10, 1, 2, 3), "pixels");
}

// ---- Learner state files ----

void WriteStateFiles(const fs::path& dir) {
  for (const rl::fuzz::FuzzLearner& l : rl::fuzz::FuzzLearners()) {
    const std::string name = l.kind.substr(l.kind.find(' ') + 1);
    WriteFile(dir / (name + "-full"), SaveLearnerState(l, 40000).Serialize());
  }
  // Small files that reach every section type quickly.
  rl::StateFile small("learner dqn");
  small.PutText("learner.env", "CartPole-v1");
  small.PutInt("learner.env_steps", 5);
  const float floats[] = {1.5f, -2};
  small.PutFloats("dqn.online", floats);
  WriteFile(dir / "dqn-partial", small.Serialize());
  WriteFile(dir / "empty-td3", rl::StateFile("learner td3").Serialize());
}

// ---- Policy checkpoints ----

void WriteCheckpoints(const fs::path& dir) {
  const char* archs[][2] = {
      {"mlp", "linear(4,8),relu,linear(8,2)"},
      {"bounded", "linear(3,8),tanh,linear(8,2),bounded(2,-1,1,0,2.5)"},
      {"dueling", "linear(6,8),relu,layernorm(8),dueling(8,4,3)"},
      {"cnn",
       "conv2d(1,2,3,1,0,6,6),batchnorm2d(2,4,4),relu,maxpool2d(2,2,4,4),flatten,linear(8,2)"},
      {"avgpool", "conv2d(2,1,2,2,1,4,4),avgpool2d(1,3,3,3),flatten,linear(1,1)"},
  };
  int64_t update = 100;
  for (const auto& [name, arch] : archs) {
    std::mt19937 rng(7);
    const rl::nn::Sequential net = rl::nn::BuildFromArchitecture(arch, &rng);
    rl::nn::Checkpoint ckpt;
    ckpt.architecture = arch;
    net.GetFlat(&ckpt.params);
    ckpt.meta.update = update;
    ckpt.meta.env_steps = 8 * update;
    ckpt.meta.wall_seconds = 1.5;
    ckpt.meta.run_id = 42;
    ckpt.meta.note = "env = CartPole-v1";
    update *= 10;
    rl::nn::SaveCheckpoint((dir / name).string(), ckpt);
  }
}

// ---- Handler targets: a selector byte, then records of encoded messages ----

template <class Msg>
std::string Encoded(const Msg& msg) {
  std::string bytes(static_cast<size_t>(msg.getEncodedSize()), '\0');
  if (msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())) !=
      static_cast<int>(bytes.size())) {
    std::fprintf(stderr, "fuzz_seeds: %s does not encode\n", Msg::getTypeName());
    std::exit(1);
  }
  return bytes;
}

// Every chunk of `versions` versions of a network of `arch` (a new version each 1000 updates, the
// parameters scaled a little), in chunks of `chunk_floats`.
std::string WeightsInput(uint8_t selector, const std::string& arch, int versions,
                         int chunk_floats) {
  std::mt19937 rng(7);
  const rl::nn::Sequential net = rl::nn::BuildFromArchitecture(arch, &rng);
  std::vector<float> params;
  net.GetFlat(&params);
  std::string input(1, static_cast<char>(selector));
  int64_t seq = 0;
  for (int v = 1; v <= versions; ++v) {
    for (float& p : params) p *= 0.9f;
    for (rlmsg::weights_chunk_t& c :
         rl::learner::MakeWeightChunks(1000 * v, arch, params, chunk_floats)) {
      c.header = rl::examples::Header("learner", seq++);
      rl::fuzz::AppendRecord(&input, Encoded(c));
    }
  }
  return input;
}

void WriteWeights(const fs::path& dir) {
  const std::string q_net = "linear(4,16),relu,linear(16,16),relu,linear(16,2)";
  WriteFile(dir / "cartpole-one-chunk", WeightsInput(0, q_net, 1, 12000));
  WriteFile(dir / "cartpole-chunks", WeightsInput(0, q_net, 2, 100));
  rl::learner::Td3Config td3;
  td3.hidden = {16, 16};
  const std::string actor =
      rl::learner::Td3ActorArchitecture(td3, rl::envs::LookupSpec("Pendulum-v1"));
  WriteFile(dir / "pendulum-chunks", WeightsInput(1, actor, 2, 150));
}

// A reply of `count` transitions of `setup`'s env (its observation size or frames, its actions:
// in range for a discrete env, spread over [-1, 1] for a continuous one).
rlmsg::sample_batch_t SampleReply(const rl::fuzz::DecoderSetup& setup, int count, int64_t id) {
  const rl::envs::EnvSpec spec = rl::envs::LookupSpec(setup.env);
  rlmsg::sample_batch_t m =
      spec.frame_stack > 0
          ? rl::examples::PixelSamples(count, spec.frame_height, spec.frame_width, spec.frame_stack,
                                       spec.action_width())
          : rl::examples::FlatSamples(count, spec.observation_size, spec.action_width());
  m.header.seq = id;
  m.request_id = id;
  for (int i = 0; i < m.num_action_values; ++i) {
    m.action[static_cast<size_t>(i)] = spec.continuous() ? 0.5f * static_cast<float>(i % 5 - 2)
                                                         : static_cast<float>(i % spec.num_actions);
  }
  return m;
}

void WriteBatchReplies(const fs::path& dir) {
  const char* names[] = {"cartpole", "pendulum", "catch-pixels"};
  for (size_t k = 0; k < std::size(rl::fuzz::kDecoderSetups); ++k) {
    std::string input(1, static_cast<char>(k));
    rl::fuzz::AppendRecord(&input, Encoded(SampleReply(rl::fuzz::kDecoderSetups[k], 4, 1)));
    rl::fuzz::AppendRecord(&input, Encoded(SampleReply(rl::fuzz::kDecoderSetups[k], 7, 2)));
    WriteFile(dir / names[k], input);
  }
}

// An announcement of `path` and the file's bytes (fuzz_announced_checkpoint.cc).
std::string Announcement(const std::string& path, const std::string& file) {
  return std::string(1, static_cast<char>(path.size())) + path + file;
}

void WriteAnnouncements(const fs::path& dir) {
  std::mt19937 rng(7);
  const rl::nn::Sequential net = rl::nn::MakeMlp(4, {8}, 2, &rng);
  rl::nn::Checkpoint ckpt;
  ckpt.architecture = net.Architecture();
  net.GetFlat(&ckpt.params);
  ckpt.meta.update = 500;
  ckpt.meta.note = "CartPole-v1";
  const fs::path tmp = dir / ".checkpoint.tmp";
  rl::nn::SaveCheckpoint(tmp.string(), ckpt);
  std::ifstream in(tmp, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(tmp);
  const std::pair<const char*, const char*> paths[] = {
      {"good", "checkpoints/ckpt.bin"},
      {"through-parent", "checkpoints/../checkpoints/ckpt.bin"},
      {"through-link", "checkpoints/up/checkpoints/ckpt.bin"},
      {"fifo", "checkpoints/fifo.bin"},
      {"link-to-zero", "checkpoints/zero.bin"},
      {"link-outside", "checkpoints/outside.bin"},
      {"outside", "outside.bin"},
      {"device", "/dev/zero"},
  };
  for (const auto& [name, path] : paths) WriteFile(dir / name, Announcement(path, file));
}

// ---- Replay snapshots ----

#ifdef RL_FUZZ_SNAPSHOT
// Batches of each replay configuration: the first of actors 0 and 2, a later one of actor 1
// (naming frames the set-up batches sent), and one of an id above max_actors.
void WriteTransitionBatches(const fs::path& dir) {
  const char* kinds[] = {"flat", "prioritized", "pixels"};
  for (int config = 0; config < rl::fuzz::kNumReplayConfigs; ++config) {
    std::string input(1, static_cast<char>(config));
    int64_t seq = 0;
    for (const auto& [first, actor] :
         {std::pair{0, 0}, std::pair{0, 2}, std::pair{6, 1}, std::pair{0, 5000}}) {
      rlmsg::transition_batch_t m = rl::fuzz::SetupBatch(config, first, 4, actor);
      m.header = rl::examples::Header("actor-fuzz", seq++);
      rl::fuzz::AppendRecord(&input, Encoded(m));
    }
    WriteFile(dir / kinds[config], input);
  }
}

// "<dir>/<kind>-<fill>": the configuration byte (replay_setup.h), then the snapshot file.
void WriteSnapshots(const fs::path& dir) {
  const char* kinds[] = {"flat", "prioritized", "pixels"};
  for (int config = 0; config < rl::fuzz::kNumReplayConfigs; ++config) {
    for (const auto& [name, batches, samples] :
         {std::tuple{"empty", 0, 0}, std::tuple{"some", 3, 2}, std::tuple{"full", 14, 4}}) {
      rl::fuzz::Replica replica(config);
      replica.Fill(batches, samples);
      rl::StateStream out(rl::replay::ReplayService::kSnapshotKind);
      replica.service().SaveSnapshot(&out);
      WriteFile(dir / (std::string(kinds[config]) + "-" + name),
                std::string(1, static_cast<char>(config)) + out.Serialize());
    }
  }
}
#endif

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds CORPUS_DIR\n");
    return 2;
  }
  const fs::path root = argv[1];
  // Replaces the generated seeds; reproducers of fixed bugs ("repro-*") stay.
  for (const char* target : {"messages", "state_file", "checkpoint", "snapshot", "weights",
                             "batch_decoder", "replay_insert", "announced_checkpoint"}) {
    fs::create_directories(root / target);
    for (const fs::directory_entry& e : fs::directory_iterator(root / target)) {
      if (e.path().filename().string().rfind("repro-", 0) != 0) fs::remove(e.path());
    }
  }
  WriteMessages(root / "messages");
  WriteStateFiles(root / "state_file");
  WriteCheckpoints(root / "checkpoint");
  WriteWeights(root / "weights");
  WriteBatchReplies(root / "batch_decoder");
  WriteAnnouncements(root / "announced_checkpoint");
#ifdef RL_FUZZ_SNAPSHOT
  WriteSnapshots(root / "snapshot");
  WriteTransitionBatches(root / "replay_insert");
#endif
  std::printf("fuzz_seeds: wrote the seeds in %s\n", root.c_str());
  return 0;
}
