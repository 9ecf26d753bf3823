#include "common/message_examples.h"

#include <algorithm>

namespace rl::examples {
namespace {

// The columns of a reply (FlatSamples, PixelSamples) other than the observations.
rlmsg::sample_batch_t Reply(int count, int action_width) {
  rlmsg::sample_batch_t m{};
  m.header = Header("replay", 0);
  m.requester = "learner";
  m.request_id = 12;
  m.count = count;
  m.action_width = action_width;
  m.num_action_values = count * action_width;
  for (int i = 0; i < count; ++i) {
    m.action.insert(m.action.end(), action_width, static_cast<float>(i % 2));
    m.reward.push_back(static_cast<float>(i % 3) - 1.0f);
    m.discount.push_back(i % 4 == 3 ? 0.0f : 0.99f);
    m.index.push_back(100 + i);
    m.weight.push_back(1.0f - 0.1f * static_cast<float>(i % 3));
  }
  m.replay_size = 500;
  m.total_inserts = 800;
  return m;
}

}  // namespace

rlmsg::header_t Header(const std::string& sender, int64_t seq) {
  rlmsg::header_t h{};
  h.run_id = 0x5eed1234abcdLL;
  h.sender = sender;
  h.seq = seq;
  h.utime = 1764072000000000LL;
  return h;
}

rlmsg::transition_batch_t FlatTransitions(int first, int count, int obs_size, int action_width,
                                          int32_t actor) {
  rlmsg::transition_batch_t m{};
  m.header = Header("actor-" + std::to_string(actor), 0);
  m.actor_id = actor;
  m.obs_size = obs_size;
  m.num_values = count * obs_size;
  m.count = count;
  m.action_width = action_width;
  m.num_action_values = count * action_width;
  for (int v = first; v < first + count; ++v) {
    for (int j = 0; j < obs_size; ++j) {
      m.obs.push_back(static_cast<float>(v) + 0.5f * static_cast<float>(j));
      m.next_obs.push_back(static_cast<float>(v) + 0.5f * static_cast<float>(j) + 1000.0f);
    }
    m.action.insert(m.action.end(), action_width, static_cast<float>(v % 2));
    m.reward.push_back(static_cast<float>(v));
    m.discount.push_back(0.99f);
    m.episode_id.push_back(v / 10);
    m.priority.push_back(static_cast<float>(v % 7) / 2.0f);
  }
  return m;
}

rlmsg::transition_batch_t PixelTransitions(int first, int count, int height, int width,
                                           int32_t actor) {
  rlmsg::transition_batch_t m{};
  m.header = Header("actor-" + std::to_string(actor), 0);
  m.actor_id = actor;
  m.height = height;
  m.width = width;
  m.stack = 2;
  m.num_frames = count + 1;
  for (int f = first; f <= first + count; ++f) {
    m.frame_id.push_back(f);
    m.frames.insert(m.frames.end(), static_cast<size_t>(height) * static_cast<size_t>(width),
                    static_cast<uint8_t>(f + actor));
  }
  m.num_bytes = static_cast<int32_t>(m.frames.size());
  m.count = count;
  m.num_refs = 2 * count;
  m.action_width = 1;
  m.num_action_values = count;
  for (int t = first; t < first + count; ++t) {
    m.obs_frames.insert(m.obs_frames.end(), {std::max(t - 1, first), t});
    m.next_obs_frames.insert(m.next_obs_frames.end(), {t, t + 1});
    m.action.push_back(static_cast<float>(t % 3));
    m.reward.push_back(static_cast<float>(t));
    m.discount.push_back(0.99f);
    m.episode_id.push_back(0);
    m.priority.push_back(0.0f);
  }
  return m;
}

rlmsg::sample_batch_t FlatSamples(int count, int obs_size, int action_width) {
  rlmsg::sample_batch_t m = Reply(count, action_width);
  m.obs_size = obs_size;
  m.num_values = count * obs_size;
  for (int e = 0; e < m.num_values; ++e) {
    m.obs.push_back(0.1f * static_cast<float>(e % 9) - 0.4f);
    m.next_obs.push_back(0.1f * static_cast<float>(e % 7) - 0.3f);
  }
  return m;
}

rlmsg::sample_batch_t PixelSamples(int count, int height, int width, int stack, int action_width) {
  rlmsg::sample_batch_t m = Reply(count, action_width);
  m.height = height;
  m.width = width;
  m.stack = stack;
  m.num_bytes = count * stack * height * width;
  for (int e = 0; e < m.num_bytes; ++e) {
    m.obs_pixels.push_back(static_cast<uint8_t>(e * 7));
    m.next_obs_pixels.push_back(static_cast<uint8_t>(e * 11));
  }
  return m;
}

rlmsg::weights_chunk_t WeightsChunk(const std::string& architecture, int32_t total_size,
                                    int32_t num_chunks, int32_t chunk_index) {
  rlmsg::weights_chunk_t m{};
  m.header = Header("learner", 0);
  m.version = 3;
  m.architecture = architecture;
  m.total_size = total_size;
  m.num_chunks = num_chunks;
  m.chunk_index = chunk_index;
  const int32_t per_chunk = (total_size + num_chunks - 1) / num_chunks;
  m.offset = chunk_index * per_chunk;
  m.count = std::min(per_chunk, total_size - m.offset);
  for (int i = 0; i < m.count; ++i) m.data.push_back(0.01f * static_cast<float>(i - 9));
  m.crc32 = 0xCBF43926LL;
  return m;
}

// ---- One example of each type ----

void MakeExample(rlmsg::checkpoint_t* m) {
  m->header = Header("learner", 7);
  m->path = "runs/cartpole/checkpoints/ckpt-000005000.bin";
  m->update = 5000;
  m->env_steps = 40000;
  m->wall_seconds = 61.5;
}

void MakeExample(rlmsg::eval_result_t* m) {
  m->header = Header("evaluator", 3);
  m->checkpoint = "runs/cartpole/checkpoints/ckpt-000005000.bin";
  m->update = 5000;
  m->env_steps = 40000;
  m->wall_seconds = 75.25;
  m->episodes = 100;
  m->mean = 487.5;
  m->std = 12.0;
  m->min = 410;
  m->max = 500;
  m->goal_reached = 1;
}

void MakeExample(rlmsg::flow_control_t* m) {
  m->header = Header("replay", 120);
  m->insert_allowed = 1;
  m->samples_per_insert = 7.5;
  m->target_samples_per_insert = 8;
  m->error_buffer = 100;
  m->insert_credit = 64;
  m->num_actors = 2;
  m->actor_id = {0, 1};
  m->actor_inserts = {1000, 998};
}

void MakeExample(rlmsg::priority_update_t* m) {
  m->header = Header("learner", 9);
  m->count = 3;
  m->index = {5, 17, 99999};
  m->priority = {0.5f, 1.25f, 0.0f};
}

void MakeExample(rlmsg::sample_batch_t* m) { *m = FlatSamples(2, 4); }

void MakeExample(rlmsg::sample_request_t* m) {
  m->header = Header("learner", 12);
  m->request_id = 12;
  m->batch_size = 64;
}

void MakeExample(rlmsg::stats_actor_t* m) {
  m->header = Header("actor-0", 30);
  m->env_steps = 4000;
  m->episodes = 50;
  m->steps_per_second = 2000;
  m->mean_return = 85.5;
  m->epsilon = 0.4;
  m->weights_version = 12;
  m->transitions_published = 3990;
}

void MakeExample(rlmsg::stats_evaluator_t* m) {
  m->header = Header("evaluator", 4);
  m->checkpoints_scored = 3;
  m->last_mean = 200;
  m->best_mean = 250;
  m->best_update = 4000;
  m->busy = 1;
}

void MakeExample(rlmsg::stats_learner_t* m) {
  m->header = Header("learner", 31);
  m->updates = 5000;
  m->updates_per_second = 150;
  m->samples_per_second = 9600;
  m->loss = 0.02;
  m->mean_q = 30;
  m->weights_version = 50;
  m->env_steps = 40000;
}

void MakeExample(rlmsg::stats_replay_t* m) {
  m->header = Header("replay", 32);
  m->size = 40000;
  m->capacity = 100000;
  m->total_inserts = 40000;
  m->total_samples = 320000;
  m->inserts_per_second = 2000;
  m->samples_per_second = 16000;
  m->samples_per_insert = 8;
  m->insert_allowed = 1;
  m->prioritized = 1;
  m->beta = 0.4;
  m->memory_bytes = 1 << 20;
}

void MakeExample(rlmsg::transition_batch_t* m) { *m = FlatTransitions(0, 2, 3, 1, 1); }

void MakeExample(rlmsg::weights_chunk_t* m) {
  *m = WeightsChunk("linear(4,8),relu,linear(8,2)", 58, 2, 1);
}

}  // namespace rl::examples
