#include "pitchlab/hw/stop_request.hpp"

#include <csignal>

#include <atomic>
#include <cstring>

namespace pitchlab::hw {
namespace {

// -1: requested without a signal; 0: not requested; > 0: the signal number.
std::atomic<int> g_stop{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void OnStopSignal(int signal) { g_stop.store(signal, std::memory_order_relaxed); }

}  // namespace

void InstallStopSignalHandlers() {
  struct sigaction action;
  std::memset(&action, 0, sizeof(action));
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking poll() returns EINTR and the loop looks
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

bool StopRequested() { return g_stop.load(std::memory_order_relaxed) != 0; }

int StopSignal() {
  const int value = g_stop.load(std::memory_order_relaxed);
  return value > 0 ? value : 0;
}

void RequestStop(int signal) { g_stop.store(signal > 0 ? signal : -1); }

void ClearStopRequest() { g_stop.store(0); }

std::string StopReason() {
  const int signal = StopSignal();
  const std::string by = signal == SIGINT    ? "SIGINT"
                         : signal == SIGTERM ? "SIGTERM"
                         : signal > 0        ? "signal " + std::to_string(signal)
                                             : "a stop request";
  return "interrupted by " + by;
}

Error StopError(const std::string& device) {
  return {Error::Code::kFailed, device + ": " + StopReason()};
}

int StopExitCode() {
  const int signal = StopSignal();
  return signal > 0 ? 128 + signal : 1;
}

}  // namespace pitchlab::hw
