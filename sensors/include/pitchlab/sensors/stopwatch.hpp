#pragma once
// Wall-clock and CPU time of a piece of work, for profiling a run (where its time goes). It is
// the one clock library code may read, and only to report: no data and no decision depends on it,
// so simulated runs stay deterministic. Here, at the bottom of the module graph, so that the
// simulator can time its own work (the laser's ray casting) and the mission the stages around it.

namespace pitchlab::sensors {

/// Time spent: wall clock (steady) and CPU time [s]: of the timing thread and the WorkerThreads
/// it hands work to (a stage's own work), or of the whole process.
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
  /// The thread that reads the Stopwatch (it must be the one that started it) and the
  /// WorkerThreads: a stage's own work. Not the threads beside it (a run's files written while
  /// the robot drives on), nor threads a library starts (Embree's scene builds): a run's "other".
  kForeground,
  kProcess,  ///< all threads: a whole run's
};

/// Started at construction (or Restart); Read() is the time since. CLOCK_MONOTONIC, and the
/// threads' own CPU clocks (nanosecond resolution on Linux; a read costs about a microsecond, so
/// a timer around each line or each control period costs nothing measurable) or
/// CLOCK_PROCESS_CPUTIME_ID. The foreground is summed from per-thread clocks, not the process's
/// less the background's: Linux brings a thread's time running on another core into the process
/// clock only at its next tick, so that difference lost up to a tick per read while work ran
/// beside (driving, timed per 2 ms control period, read 0.4 s of CPU for 1.9 s of stepping).
class Stopwatch {
 public:
  explicit Stopwatch(CpuOf cpu = CpuOf::kForeground) : cpu_(cpu) { Restart(); }
  void Restart();
  [[nodiscard]] Elapsed Read() const;

 private:
  CpuOf cpu_;
  Elapsed start_;  // the clocks' readings at the start
};

/// Marks the calling thread, for this object's lifetime, as a worker of whichever thread hands it
/// work (a parallel loop's helper): its CPU time counts to the foreground's stages. One per
/// thread, made and ended on it.
class WorkerThread {
 public:
  WorkerThread();
  ~WorkerThread();
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

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
