// DQN updates per second for the CartPole MLP (4-120-84-2) at batch 32, 64 and 128, one thread:
// forward of the target network on s', forward and backward of the online network on s, Adam
// step. The same update as the PyTorch peer's "updates" (MSE loss, lr 2.5e-4, 8 batches cycled,
// max over the target network, no target refresh during the measurement).
#include <random>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "learner/dqn.h"

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 5;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 1.0;
  for (int batch : {32, 64, 128}) {
    rl::learner::DqnConfig c;
    c.hidden = {120, 84};
    c.loss = "mse";
    c.learning_rate = 2.5e-4f;
    c.double_dqn = false;
    c.max_grad_norm = 0;
    c.target_update_period = 1 << 30;
    rl::learner::Dqn dqn(4, 2, c);
    // Eight batches of random data, cycled.
    std::mt19937 rng(1);
    std::normal_distribution<float> normal;
    std::bernoulli_distribution done(0.05);
    struct Data {
      std::vector<float> obs, next_obs, reward, discount;
      std::vector<int32_t> action;
    };
    std::vector<Data> data(8);
    for (Data& d : data) {
      for (int i = 0; i < 4 * batch; ++i) {
        d.obs.push_back(normal(rng));
        d.next_obs.push_back(normal(rng));
      }
      for (int i = 0; i < batch; ++i) {
        d.action.push_back(static_cast<int32_t>(rng() & 1U));
        d.reward.push_back(1.0f);
        d.discount.push_back(done(rng) ? 0.0f : 0.99f);
      }
    }
    size_t k = 0;
    const auto s = rl::bench::Repeat(repeats, [&] {
      return rl::bench::Rate(
          [&] {
            const Data& d = data[k++ % data.size()];
            rl::learner::BatchView b;
            b.obs_size = 4;
            b.count = batch;
            b.obs = d.obs.data();
            b.next_obs = d.next_obs.data();
            b.action = d.action.data();
            b.reward = d.reward.data();
            b.discount = d.discount.data();
            dqn.Update(b);
          },
          1, seconds, 20);
    });
    rl::bench::Emit("learner_updates_mlp", "updates/s", s, repeats,
                    "\"batch\": " + std::to_string(batch) + ", \"threads\": 1");
  }
  return 0;
}
