#include "pitchlab/mapping/parallel_for.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "pitchlab/sensors/allowed_cores.hpp"
#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::mapping {
namespace {

constexpr unsigned kMaxThreads = 8;  // beyond the 2-8 cores this runs on, blocks get too few

thread_local bool serial_loops = false;  // SerialLoops

// One loop's blocks and who works on them. Helpers hold it by shared_ptr: one that starts after
// the caller closed the job returns without touching `body`, which lives on the caller's stack.
struct Job {
  std::size_t n = 0, block = 1, blocks = 0;
  const std::function<void(std::size_t, std::size_t)>* body = nullptr;
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::condition_variable idle;
  bool closed = false;
  int running = 0;  // helpers inside Work
  std::exception_ptr failure;  // the first helper's exception

  void Work() {
    for (std::size_t b = next++; b < blocks; b = next++) {
      (*body)(b * block, std::min(n, (b + 1) * block));
    }
  }
  void Help() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (closed) return;
      ++running;
    }
    std::exception_ptr error;
    try {
      Work();
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (error && !failure) failure = error;
    if (--running == 0) idle.notify_all();
  }
};

// Helper threads kept for the process's life: a loop of ICP's pair search lasts ~0.2-1 ms and
// registration runs hundreds of them, and starting a thread for each (std::async) cost ~60 us of
// every call. Started by the first loop that wants them (they share its thread's priority: the
// mission's, not the nicer side work's, which runs no loops), as many as the cores then allowed
// minus the caller's, at most kMaxThreads - 1.
class HelperThreads {
 public:
  static HelperThreads& Get() {
    static HelperThreads helpers(std::min(sensors::AllowedCores(), kMaxThreads) - 1);
    return helpers;
  }
  ~HelperThreads() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  // Queues `job`'s help for one thread; false when there are no helper threads.
  bool Post(const std::shared_ptr<Job>& job) {
    if (threads_.empty()) return false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(job);
    }
    wake_.notify_one();
    return true;
  }

 private:
  explicit HelperThreads(unsigned count) {
    try {
      for (unsigned i = 0; i < count; ++i) threads_.emplace_back([this] { Run(); });
    } catch (const std::system_error&) {  // no more threads to be had: fewer helpers
    }
  }
  void Run() {
    const sensors::WorkerThread worker;  // its loops' time is the stage's that runs them
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      const std::shared_ptr<Job> job = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      job->Help();
      lock.lock();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Job>> queue_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace

void ParallelFor(std::size_t n, std::size_t block,
                 const std::function<void(std::size_t begin, std::size_t end)>& body,
                 unsigned max_threads) {
  if (n == 0) return;
  auto job = std::make_shared<Job>();
  job->n = n;
  job->block = std::max<std::size_t>(block, 1);
  job->blocks = (n + job->block - 1) / job->block;
  job->body = &body;
  const unsigned cores = serial_loops ? 1u : std::min(sensors::AllowedCores(), kMaxThreads);
  const unsigned threads = static_cast<unsigned>(
      std::min<std::size_t>(job->blocks, max_threads > 0 ? std::min(max_threads, cores) : cores));
  for (unsigned t = 1; t < threads; ++t) {
    if (!HelperThreads::Get().Post(job)) break;  // none: the calling thread does it all
  }
  // The caller's own share; then no helper may start, and those at work are waited for, whether
  // the caller's share ended in an exception (which then propagates) or not (a helper's does).
  std::exception_ptr own;
  try {
    job->Work();
  } catch (...) {
    own = std::current_exception();
  }
  std::unique_lock<std::mutex> lock(job->mutex);
  job->closed = true;
  job->idle.wait(lock, [&job] { return job->running == 0; });
  if (own) std::rethrow_exception(own);
  if (job->failure) std::rethrow_exception(job->failure);
}

SerialLoops::SerialLoops() : was_(serial_loops) { serial_loops = true; }
SerialLoops::~SerialLoops() { serial_loops = was_; }

}  // namespace pitchlab::mapping
