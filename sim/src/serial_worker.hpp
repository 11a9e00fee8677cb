#pragma once
// One thread that runs posted jobs one after another, in the order posted: work handed off the
// simulation's thread so that it overlaps the physics (SimLineScanner's ray casting), with the
// jobs' own order kept (the laser model's noise is drawn from one generator, line after line).

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace pitchlab::sim {

class SerialWorker {
 public:
  SerialWorker();
  /// Waits for the jobs posted (their exceptions dropped), then ends the thread.
  ~SerialWorker();
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  /// Queues `job`; it runs after every job posted before it.
  void Post(std::function<void()> job);
  /// Returns once every job posted has run; rethrows the first exception one threw since the
  /// last Wait (the jobs after it still ran).
  void Wait();
  /// CPU time the jobs have taken so far [s] (read it after Wait: exact then).
  double cpu_s() const;

 private:
  void Run();

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<std::function<void()>> queue_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr failure_;
  double cpu_s_ = 0;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace pitchlab::sim
