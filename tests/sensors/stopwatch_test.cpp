// Stopwatch's CPU time: a stage's own (the timing thread's and its WorkerThreads'), however
// finely it is read while other threads work beside it.

#include "pitchlab/sensors/stopwatch.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace pitchlab::sensors {
namespace {

void SpinFor(double cpu_s) {
  const double start = ThreadCpuSeconds();
  volatile double sink = 0;
  while (ThreadCpuSeconds() - start < cpu_s) sink = sink + 1;
}

// Read every 2 ms (a mission's control period) while a thread spins beside: summed, the
// foreground CPU time is the timing thread's own. (Read as the process's time less the other
// thread's, it came to ~0: Linux adds another core's running time to the process clock at its
// next tick only.)
TEST(Stopwatch, ForegroundTimeReadFinelyIsTheTimingThreadsOwn) {
  std::atomic<bool> stop{false};
  std::thread beside([&] {
    volatile double sink = 0;
    while (!stop.load()) sink = sink + 1;
  });
  double foreground_s = 0;
  const double own_start = ThreadCpuSeconds();
  for (int i = 0; i < 200; ++i) {
    const Stopwatch watch;
    SpinFor(0.002);
    foreground_s += watch.Read().cpu_s;
  }
  const double own_s = ThreadCpuSeconds() - own_start;
  stop = true;
  beside.join();
  EXPECT_NEAR(foreground_s, own_s, 0.05 * own_s);
}

// A WorkerThread's CPU time is the foreground's; an unmarked thread's is not; the process's
// counts both.
TEST(Stopwatch, CountsWorkerThreadsAndLeavesOtherThreadsOut) {
  const Stopwatch foreground, process(CpuOf::kProcess);
  std::thread([] {
    const WorkerThread worker;
    SpinFor(0.2);
  }).join();
  const double with_worker = foreground.Read().cpu_s;
  std::thread([] { SpinFor(0.2); }).join();
  const double with_other = foreground.Read().cpu_s;
  EXPECT_GE(with_worker, 0.2);
  EXPECT_LT(with_other - with_worker, 0.05);
  EXPECT_GE(process.Read().cpu_s, 0.4);
}

}  // namespace
}  // namespace pitchlab::sensors
