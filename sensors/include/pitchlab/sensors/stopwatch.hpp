#pragma once
// Wall-clock and CPU time of a piece of work, for profiling a run (where its time goes). It is
// the one clock library code may read, and only to report: no data and no decision depends on it,
// so simulated runs stay deterministic. Here, at the bottom of the module graph, so that the
// simulator can time its own work (the laser's ray casting) and the mission the stages around it.

namespace pitchlab::sensors {

/// Time spent: wall clock (steady) and CPU time of the whole process, i.e. all its threads, so
/// that work a library hands to worker threads (Embree's scene builds) is counted too, except
/// threads marked BackgroundThread: work beside the timed one is not its time [s].
struct Elapsed {
  double wall_s = 0;
  double cpu_s = 0;
  Elapsed& operator+=(const Elapsed& o) {
    wall_s += o.wall_s;
    cpu_s += o.cpu_s;
    return *this;
  }
  Elapsed& operator-=(const Elapsed& o) {
    wall_s -= o.wall_s;
    cpu_s -= o.cpu_s;
    return *this;
  }
  friend Elapsed operator+(Elapsed a, const Elapsed& b) { return a += b; }
  friend Elapsed operator-(Elapsed a, const Elapsed& b) { return a -= b; }
};

/// Which threads' CPU time a Stopwatch counts.
enum class CpuOf {
  kForeground,  ///< all but BackgroundThreads: a stage's own work
  kProcess,     ///< all: a whole run's
};

/// Started at construction (or Restart); Read() is the time since. CLOCK_MONOTONIC and
/// CLOCK_PROCESS_CPUTIME_ID less the background threads' CPU clocks (nanosecond resolution on
/// Linux; a read costs about a microsecond, so a timer around each line or each control period
/// costs nothing measurable).
class Stopwatch {
 public:
  explicit Stopwatch(CpuOf cpu = CpuOf::kForeground) : cpu_(cpu) { Restart(); }
  void Restart();
  [[nodiscard]] Elapsed Read() const;

 private:
  CpuOf cpu_;
  Elapsed start_;  // the clocks' readings at the start
};

/// Marks the calling thread, for this object's lifetime, as background work: work that runs
/// beside the stages Stopwatches time (a run's files written while the robot drives on), whose
/// CPU time is its own to report (ThreadCpuSeconds), not theirs. One per thread, made and ended on
/// it.
class BackgroundThread {
 public:
  BackgroundThread();
  ~BackgroundThread();
  BackgroundThread(const BackgroundThread&) = delete;
  BackgroundThread& operator=(const BackgroundThread&) = delete;

 private:
  int clock_;  // the thread's CPU clock (a clockid_t)
};

/// CPU time of the calling thread [s].
double ThreadCpuSeconds();

/// Adds the time of its own lifetime to `total` when it ends: `{ ScopedTime t(total); work(); }`.
class ScopedTime {
 public:
  explicit ScopedTime(Elapsed& total) : total_(total) {}
  ~ScopedTime() { total_ += watch_.Read(); }
  ScopedTime(const ScopedTime&) = delete;
  ScopedTime& operator=(const ScopedTime&) = delete;

 private:
  Elapsed& total_;
  Stopwatch watch_;
};

}  // namespace pitchlab::sensors
