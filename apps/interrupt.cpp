#include "interrupt.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <mutex>
#include <thread>

#include "pitchlab/mission/cleanup_registry.hpp"

namespace pitchlab::apps {
namespace {

std::mutex g_mutex;
std::string g_command = "pitchlab";
std::once_flag g_installed;

sigset_t InterruptSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

[[noreturn]] void Watch() {
  const sigset_t set = InterruptSignals();
  int signal = 0;
  while (sigwait(&set, &signal) != 0) {
  }
  std::string command;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    command = g_command;
  }
  const char* name = signal == SIGINT ? "SIGINT" : "SIGTERM";
  std::fprintf(stderr, "\n%s: interrupted by %s; cleaning up\n", command.c_str(), name);
  for (const std::string& what : mission::RunCleanups(signal)) {
    std::fprintf(stderr, "%s: removed %s\n", command.c_str(), what.c_str());
  }
  std::fflush(stderr);
  ::_exit(128 + signal);
}

}  // namespace

void InstallInterruptCleanup(const std::string& command) {
  std::call_once(g_installed, [&command] {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      g_command = command;
    }
    const sigset_t set = InterruptSignals();
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread(Watch).detach();
  });
}

}  // namespace pitchlab::apps
