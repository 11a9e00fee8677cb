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

// The background threads: the CPU clocks of those running, and the CPU time of those that ended
// (still in the process's CPU time).
struct Background {
  std::mutex mutex;
  std::vector<clockid_t> running;
  double ended_s = 0;
};
Background& TheBackground() {
  static Background background;
  return background;
}

double BackgroundCpuSeconds() {
  Background& b = TheBackground();
  std::lock_guard<std::mutex> lock(b.mutex);
  double total = b.ended_s;
  for (const clockid_t c : b.running) total += Seconds(c);
  return total;
}

Elapsed Now(CpuOf cpu) {
  double cpu_s = Seconds(CLOCK_PROCESS_CPUTIME_ID);
  if (cpu == CpuOf::kForeground) cpu_s -= BackgroundCpuSeconds();
  return {Seconds(CLOCK_MONOTONIC), cpu_s};
}

}  // namespace

void Stopwatch::Restart() { start_ = Now(cpu_); }

Elapsed Stopwatch::Read() const { return Now(cpu_) - start_; }

BackgroundThread::BackgroundThread() {
  clockid_t clock{};
  pthread_getcpuclockid(pthread_self(), &clock);  // cannot fail for the calling thread
  clock_ = clock;
  Background& b = TheBackground();
  std::lock_guard<std::mutex> lock(b.mutex);
  b.running.push_back(clock);
}

BackgroundThread::~BackgroundThread() {
  Background& b = TheBackground();
  std::lock_guard<std::mutex> lock(b.mutex);
  b.ended_s += Seconds(clock_);
  b.running.erase(std::find(b.running.begin(), b.running.end(), clock_));
}

double ThreadCpuSeconds() { return Seconds(CLOCK_THREAD_CPUTIME_ID); }

}  // namespace pitchlab::sensors
