#include "nn/action_value_net.h"

#include <stdexcept>
#include <utility>

#include "common/check.h"

namespace rl::nn {
namespace {

// The output size of a branch: its own, or its input's when it is empty (the identity).
int BranchOutput(const Sequential& branch, int input) {
  return branch.num_layers() == 0 ? input : branch.OutputSize();
}

void CheckBranch(const Sequential& branch, int input, const char* what) {
  if (branch.num_layers() > 0 && branch.InputSize() != input) {
    throw std::invalid_argument(std::string("action-value net: the ") + what + " branch takes " +
                                std::to_string(branch.InputSize()) + " inputs, not " +
                                std::to_string(input));
  }
}

}  // namespace

ActionValueNet::ActionValueNet(Sequential obs_branch, Sequential action_branch, Sequential head,
                               int obs_size, int action_size)
    : obs_branch_(std::move(obs_branch)),
      action_branch_(std::move(action_branch)),
      head_(std::move(head)),
      obs_size_(obs_size),
      action_size_(action_size) {
  if (obs_size < 1 || action_size < 1) {
    throw std::invalid_argument("action-value net: needs observations and actions");
  }
  CheckBranch(obs_branch_, obs_size, "obs");
  CheckBranch(action_branch_, action_size, "action");
  features_ = BranchOutput(obs_branch_, obs_size);
  action_features_ = BranchOutput(action_branch_, action_size);
  if (head_.num_layers() == 0 || head_.InputSize() != features_ + action_features_ ||
      head_.OutputSize() != 1) {
    throw std::invalid_argument(
        "action-value net: the head must take " + std::to_string(features_ + action_features_) +
        " inputs (features and action) and give 1 output; it takes " +
        std::to_string(head_.InputSize()) + " and gives " + std::to_string(head_.OutputSize()));
  }
}

ActionValueNet::ActionValueNet(const ActionValueNet& other)
    : obs_branch_(other.obs_branch_),
      action_branch_(other.action_branch_),
      head_(other.head_),
      obs_size_(other.obs_size_),
      action_size_(other.action_size_),
      features_(other.features_),
      action_features_(other.action_features_) {}

ActionValueNet& ActionValueNet::operator=(const ActionValueNet& other) {
  if (this != &other) *this = ActionValueNet(other);
  return *this;
}

std::vector<Sequential*> ActionValueNet::Parts() { return {&obs_branch_, &action_branch_, &head_}; }
std::vector<const Sequential*> ActionValueNet::Parts() const {
  return {&obs_branch_, &action_branch_, &head_};
}

const Matrix& ActionValueNet::Forward(const Matrix& obs, const Matrix& act) {
  RL_CHECK(obs.rows() == obs_size_ && act.rows() == action_size_ && obs.cols() == act.cols())
      << "action-value net: inputs " << obs.rows() << "x" << obs.cols() << " and " << act.rows()
      << "x" << act.cols() << ", expected " << obs_size_ << " and " << action_size_ << " rows";
  obs_ = &obs;
  act_ = &act;
  const Matrix& f = obs_branch_.num_layers() == 0 ? obs : obs_branch_.Forward(obs);
  const Matrix& g = action_branch_.num_layers() == 0 ? act : action_branch_.Forward(act);
  joined_.resize(features_ + action_features_, obs.cols());
  joined_.topRows(features_) = f;
  joined_.bottomRows(action_features_) = g;
  return head_.Forward(joined_);
}

void ActionValueNet::BackwardImpl(const Matrix& grad_q, bool obs_gradient) {
  const Matrix& grad_joined = head_.Backward(grad_q);
  grad_action_features_ = grad_joined.bottomRows(action_features_);
  grad_action_ = action_branch_.num_layers() == 0 ? &grad_action_features_
                                                  : &action_branch_.Backward(grad_action_features_);
  grad_features_ = grad_joined.topRows(features_);
  if (obs_branch_.num_layers() == 0) {
    grad_obs_ = &grad_features_;
  } else if (obs_gradient) {
    grad_obs_ = &obs_branch_.Backward(grad_features_);
  } else {
    obs_branch_.BackwardParams(grad_features_);
    grad_obs_ = nullptr;
  }
}

void ActionValueNet::Backward(const Matrix& grad_q) { BackwardImpl(grad_q, true); }
void ActionValueNet::BackwardParams(const Matrix& grad_q) { BackwardImpl(grad_q, false); }

void ActionValueNet::ZeroGrad() {
  for (Sequential* part : Parts()) part->ZeroGrad();
}

namespace {

// Every part's items (Params or Buffers), each name prefixed with its part's: obs., act., head.
template <class Item, class Get>
std::vector<Item> Prefixed(const std::vector<Sequential*>& parts, Get get) {
  std::vector<Item> all;
  const char* prefixes[] = {"obs.", "act.", "head."};
  for (size_t k = 0; k < parts.size(); ++k) {
    for (Item item : get(parts[k])) {
      item.name = prefixes[k] + item.name;
      all.push_back(std::move(item));
    }
  }
  return all;
}

}  // namespace

std::vector<Param> ActionValueNet::Params() {
  return Prefixed<Param>(Parts(), [](Sequential* s) { return s->Params(); });
}

std::vector<Buffer> ActionValueNet::Buffers() {
  return Prefixed<Buffer>(Parts(), [](Sequential* s) { return s->Buffers(); });
}

void ActionValueNet::set_precision(Precision precision) {
  for (Sequential* part : Parts()) part->set_precision(precision);
}

void ActionValueNet::set_training(bool training) {
  for (Sequential* part : Parts()) part->set_training(training);
}

std::string ActionValueNet::Architecture() const {
  return obs_branch_.Architecture() + "|" + action_branch_.Architecture() + "|" +
         head_.Architecture();
}

int64_t ActionValueNet::FlatSize() const {
  int64_t n = 0;
  for (const Sequential* part : Parts()) n += part->FlatSize();
  return n;
}

void ActionValueNet::GetFlat(std::vector<float>* out) const {
  // All parameters first, then all buffers, as Sequential's layout.
  out->clear();
  std::vector<float> part_flat;
  for (const Sequential* part : Parts()) {
    part->GetFlat(&part_flat);
    out->insert(out->end(), part_flat.begin(), part_flat.begin() + part->NumParams());
  }
  for (const Sequential* part : Parts()) {
    part->GetFlat(&part_flat);
    out->insert(out->end(), part_flat.begin() + part->NumParams(), part_flat.end());
  }
}

void ActionValueNet::SetFlat(const float* data, size_t n) {
  if (static_cast<int64_t>(n) != FlatSize()) {
    throw std::invalid_argument("action-value net: " + std::to_string(n) +
                                " values for a network of " + std::to_string(FlatSize()));
  }
  int64_t params = 0;
  for (const Sequential* part : Parts()) params += part->NumParams();
  std::vector<float> part_flat;
  const float* p = data;
  const float* b = data + params;
  for (Sequential* part : Parts()) {
    part_flat.assign(p, p + part->NumParams());
    part_flat.insert(part_flat.end(), b, b + part->NumBuffers());
    part->SetFlat(part_flat.data(), part_flat.size());
    p += part->NumParams();
    b += part->NumBuffers();
  }
}

void ActionValueNet::CopyParamsFrom(const ActionValueNet& other) {
  obs_branch_.CopyParamsFrom(other.obs_branch_);
  action_branch_.CopyParamsFrom(other.action_branch_);
  head_.CopyParamsFrom(other.head_);
}

void ActionValueNet::SoftUpdateFrom(const ActionValueNet& other, float tau) {
  obs_branch_.SoftUpdateFrom(other.obs_branch_, tau);
  action_branch_.SoftUpdateFrom(other.action_branch_, tau);
  head_.SoftUpdateFrom(other.head_, tau);
}

ActionValueNet BuildActionValueNet(const std::string& arch, int obs_size, int action_size,
                                   std::mt19937* rng) {
  const size_t first = arch.find('|');
  const size_t second = first == std::string::npos ? first : arch.find('|', first + 1);
  if (second == std::string::npos || arch.find('|', second + 1) != std::string::npos) {
    throw std::invalid_argument("action-value net '" + arch +
                                "': expected <obs branch>|<action branch>|<head>");
  }
  const auto part = [&](size_t begin, size_t end) {
    const std::string text = arch.substr(begin, end - begin);
    return text.find_first_not_of(" \t") == std::string::npos ? Sequential()
                                                              : BuildFromArchitecture(text, rng);
  };
  Sequential obs = part(0, first);
  Sequential act = part(first + 1, second);
  Sequential head = part(second + 1, arch.size());
  return ActionValueNet(std::move(obs), std::move(act), std::move(head), obs_size, action_size);
}

}  // namespace rl::nn
