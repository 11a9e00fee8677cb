#include "background_jobs.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <utility>

#include "pitchlab/mapping/parallel_for.hpp"
#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::mission {

BackgroundJobs::BackgroundJobs() : thread_([this] { Run(); }) {}

BackgroundJobs::~BackgroundJobs() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    queue_.clear();
  }
  changed_.notify_all();
  thread_.join();
}

void BackgroundJobs::Post(std::function<void()> job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ThrowIfFailed();
    queue_.push_back(std::move(job));
  }
  changed_.notify_all();
}

void BackgroundJobs::Wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return (queue_.empty() && !busy_) || failure_; });
  ThrowIfFailed();
}

void BackgroundJobs::ThrowIfFailed() {
  if (failure_) std::rethrow_exception(failure_);
}

// The side work yields the cores to the mission: its registration runs on all of them, and a side
// job holding one meanwhile (the ground truth, a stop's pictures) slows it; the side work catches
// up while the mission steps its physics on one core, and the run waits for what is left at its
// end (default run, 3 runs each alternating: registration 3.71 -> 3.42 s wall, run 9.83 ->
// 9.36 s). A nice value is per thread on Linux (and inherited by the threads this one starts);
// lowering one's own priority needs no privilege, and where it is refused the jobs run as before.
namespace {
void LowerThisThreadsPriority() {
  constexpr int kNicer = 10, kNicest = 19;  // Linux nice values: -20 (first) .. 19 (last)
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, tid);
  if (errno == 0) setpriority(PRIO_PROCESS, tid, std::min(kNicest, nice + kNicer));
}
}  // namespace

void BackgroundJobs::Run() {
  LowerThisThreadsPriority();
  // Its loops (a stop picture's layers, the truth's) stay on this thread: the helper threads run
  // at the mission's priority and would hand the side work the cores the mission waits for.
  const mapping::SerialLoops alone;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    std::function<void()> job = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    std::exception_ptr failure;
    try {
      job();
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    busy_ = false;
    if (failure && !failure_) {
      failure_ = failure;
      queue_.clear();
    }
    changed_.notify_all();
  }
}

}  // namespace pitchlab::mission
