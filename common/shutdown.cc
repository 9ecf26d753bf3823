#include "common/shutdown.h"

#include <atomic>
#include <csignal>

namespace rl {
namespace {

std::atomic<bool> g_stop{false};

extern "C" void OnStopSignal(int /*signum*/) { g_stop.store(true); }

}  // namespace

void InstallStopHandlers() {
  struct sigaction sa = {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGUSR2, &sa, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

bool StopRequested() { return g_stop.load(); }

void RequestStop() { g_stop.store(true); }

}  // namespace rl
