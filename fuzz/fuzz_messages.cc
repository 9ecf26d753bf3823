// Fuzz target: what every receiver does with a message's bytes, for each type of
// common/channels.h: rl::Decode<Msg>() (prescan of every length against the buffer, lcm-gen's
// decoder, every byte used), then rl::Validate(). Input: one byte selecting the type (its index
// in RL_MESSAGES, modulo their count), then the encoded message as it travels on its channel
// (fingerprint first).
//
// Beyond "no crash, no leak, no UB, no huge allocation", a decoded message must survive the round
// trip: re-encoded it has the input's size, decodes again and validates the same way. A
// difference means the prescan and lcm-gen's decoder disagree about the format.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "common/messages.h"

namespace {

[[noreturn]] void Fail(const char* type, const char* what) {
  std::fprintf(stderr, "fuzz_messages: %s: %s\n", type, what);
  std::abort();
}

bool SameReason(const char* a, const char* b) {
  return (a == nullptr) == (b == nullptr) && (a == nullptr || std::strcmp(a, b) == 0);
}

template <class Msg>
void Check(const uint8_t* data, size_t size) {
  Msg msg;
  if (rl::Decode(data, size, &msg) != nullptr) return;
  const char* why = rl::Validate(msg);

  const int encoded_size = msg.getEncodedSize();
  if (encoded_size < 0 || static_cast<size_t>(encoded_size) != size) {
    Fail(Msg::getTypeName(), "re-encoded size differs from the decoded bytes");
  }
  std::vector<uint8_t> again(size);
  if (msg.encode(again.data(), 0, encoded_size) != encoded_size) {
    Fail(Msg::getTypeName(), "does not re-encode");
  }
  Msg msg2;
  if (rl::Decode(again.data(), again.size(), &msg2) != nullptr) {
    Fail(Msg::getTypeName(), "re-encoded message does not decode");
  }
  if (!SameReason(why, rl::Validate(msg2))) {
    Fail(Msg::getTypeName(), "re-encoded message validates differently");
  }
}

using CheckFn = void (*)(const uint8_t*, size_t);
#define RL_FUZZ_CHECK(type, constant, name, port) Check<rlmsg::type>,
constexpr CheckFn kChecks[] = {RL_MESSAGES(RL_FUZZ_CHECK)};
#undef RL_FUZZ_CHECK

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  kChecks[data[0] % rl::kNumMessages](data + 1, size - 1);
  return 0;
}
