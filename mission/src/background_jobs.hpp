#pragma once
// Private: one thread that runs a run's side work (its ground truth, each stop's files) beside the
// mission, so the robot drives on while they are made.

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace pitchlab::mission {

/// Runs posted jobs one after another, in order, on a thread of its own, whose CPU time the stages
/// timed meanwhile leave out (sensors::CpuOf::kForeground); each job measures its own
/// (sensors::ThreadCpuSeconds). Not copyable.
class BackgroundJobs {
 public:
  BackgroundJobs();
  /// Jobs not yet started are dropped; waits for the one running.
  ~BackgroundJobs();
  BackgroundJobs(const BackgroundJobs&) = delete;
  BackgroundJobs& operator=(const BackgroundJobs&) = delete;

  /// Queues `job`. Throws the exception an earlier job ended with, if one did (later jobs are then
  /// dropped: a run whose files cannot be written stops).
  void Post(std::function<void()> job);
  /// Waits until every job posted has run; throws the first exception one ended with.
  void Wait();

 private:
  void Run();
  void ThrowIfFailed();  // with mutex_ held

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> queue_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr failure_;
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace pitchlab::mission
