#include "pitchlab/mission/cleanup_registry.hpp"

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <thread>
#include <utility>

namespace pitchlab::mission {
namespace {

struct Cleanup {
  std::function<bool(int)> run;
  std::string what;
};

std::mutex g_mutex;
std::map<int, Cleanup> g_cleanups;  // by id; ids grow, so newest last
int g_next_id = 0;
std::atomic<bool> g_interrupted{false};

}  // namespace

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

std::vector<std::string> RunCleanups(int signal) {
  g_interrupted = true;
  std::vector<Cleanup> cleanups;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    for (auto it = g_cleanups.rbegin(); it != g_cleanups.rend(); ++it)
      cleanups.push_back(it->second);
  }
  std::vector<std::string> removed;
  for (const Cleanup& c : cleanups) {
    if (c.run(signal) && !c.what.empty()) removed.push_back(c.what);
  }
  return removed;
}

void WaitIfInterrupted() {
  while (g_interrupted) std::this_thread::sleep_for(std::chrono::seconds(1));
}

}  // namespace pitchlab::mission
