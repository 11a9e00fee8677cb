#include "pitchlab/sensors/stopwatch.hpp"

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <mutex>
#include <vector>

namespace pitchlab::sensors {
namespace {

double Seconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);  // cannot fail for these clocks on Linux
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Threads whose CPU clocks are read together: the CPU clocks of those running, and the CPU time
// of those that ended.
struct ThreadClocks {
  std::mutex mutex;
  std::vector<clockid_t> running;
  double ended_s = 0;

  void Add(clockid_t clock) {
    std::lock_guard<std::mutex> lock(mutex);
    running.push_back(clock);
  }
  void Remove(clockid_t clock) {
    std::lock_guard<std::mutex> lock(mutex);
    ended_s += Seconds(clock);
    running.erase(std::find(running.begin(), running.end(), clock));
  }
  double Total() {
    std::lock_guard<std::mutex> lock(mutex);
    double total = ended_s;
    for (const clockid_t c : running) total += Seconds(c);
    return total;
  }
};
// Never destroyed: worker threads kept for the process's life end during static destruction.
ThreadClocks& TheWorkers() {
  static ThreadClocks* const workers = new ThreadClocks;
  return *workers;
}

clockid_t CallingThreadsClock() {
  clockid_t clock{};
  pthread_getcpuclockid(pthread_self(), &clock);  // cannot fail for the calling thread
  return clock;
}

Elapsed Now(CpuOf cpu) {
  const double cpu_s = cpu == CpuOf::kProcess
                           ? Seconds(CLOCK_PROCESS_CPUTIME_ID)
                           : Seconds(CLOCK_THREAD_CPUTIME_ID) + TheWorkers().Total();
  return {Seconds(CLOCK_MONOTONIC), cpu_s};
}

}  // namespace

void Stopwatch::Restart() { start_ = Now(cpu_); }

Elapsed Stopwatch::Read() const { return Now(cpu_) - start_; }

WorkerThread::WorkerThread() : clock_(CallingThreadsClock()) { TheWorkers().Add(clock_); }
WorkerThread::~WorkerThread() { TheWorkers().Remove(clock_); }

double ThreadCpuSeconds() { return Seconds(CLOCK_THREAD_CPUTIME_ID); }

}  // namespace pitchlab::sensors
