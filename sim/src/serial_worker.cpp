#include "serial_worker.hpp"

#include <utility>

#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::sim {

SerialWorker::SerialWorker() : thread_([this] { Run(); }) {}

SerialWorker::~SerialWorker() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void SerialWorker::Post(std::function<void()> job) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void SerialWorker::Wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
}

double SerialWorker::cpu_s() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return cpu_s_;
}

void SerialWorker::Run() {
  // Its CPU time counts to the stage that waits for it (sensors::Stopwatch's foreground).
  const sensors::WorkerThread worker;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, every job done
    std::function<void()> job = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    const double cpu0 = sensors::ThreadCpuSeconds();
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    const double cpu = sensors::ThreadCpuSeconds() - cpu0;
    lock.lock();
    cpu_s_ += cpu;
    if (error && !failure_) failure_ = error;
    busy_ = false;
    if (queue_.empty()) idle_.notify_all();
  }
}

}  // namespace pitchlab::sim
