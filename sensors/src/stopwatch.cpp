#include "pitchlab/sensors/stopwatch.hpp"

#include <time.h>

namespace pitchlab::sensors {
namespace {

double Seconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);  // cannot fail for these two clocks on Linux
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

Elapsed Now() { return {Seconds(CLOCK_MONOTONIC), Seconds(CLOCK_PROCESS_CPUTIME_ID)}; }

}  // namespace

void Stopwatch::Restart() { start_ = Now(); }

Elapsed Stopwatch::Read() const { return Now() - start_; }

}  // namespace pitchlab::sensors
