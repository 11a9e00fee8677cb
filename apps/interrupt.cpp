#include "interrupt.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace pitchlab::apps {
namespace {

struct Cleanup {
  std::function<bool(int)> run;
  std::string what;
};

std::mutex g_mutex;
std::map<int, Cleanup> g_cleanups;  // by id; ids grow, so newest last
int g_next_id = 0;
std::string g_command = "pitchlab";
std::atomic<bool> g_interrupted{false};
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
  g_interrupted = true;
  std::vector<Cleanup> cleanups;
  std::string command;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    for (auto it = g_cleanups.rbegin(); it != g_cleanups.rend(); ++it) cleanups.push_back(it->second);
    command = g_command;
  }
  const char* name = signal == SIGINT ? "SIGINT" : "SIGTERM";
  std::fprintf(stderr, "\n%s: interrupted by %s; cleaning up\n", command.c_str(), name);
  for (const Cleanup& c : cleanups) {
    if (c.run(signal) && !c.what.empty()) std::fprintf(stderr, "%s: removed %s\n", command.c_str(), c.what.c_str());
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

int RegisterCleanup(std::function<bool(int signal)> cleanup, std::string what) {
  std::lock_guard<std::mutex> lock(g_mutex);
  const int id = g_next_id++;
  g_cleanups[id] = Cleanup{std::move(cleanup), std::move(what)};
  return id;
}

void UnregisterCleanup(int id) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_cleanups.erase(id);
}

void WaitIfInterrupted() {
  while (g_interrupted) std::this_thread::sleep_for(std::chrono::seconds(1));
}

}  // namespace pitchlab::apps
