#include "background_jobs.hpp"

#include <utility>

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

void BackgroundJobs::Run() {
  const sensors::BackgroundThread background;
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
