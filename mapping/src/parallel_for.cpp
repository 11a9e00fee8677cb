#include "parallel_for.hpp"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <future>
#include <system_error>
#include <thread>
#include <vector>

namespace pitchlab::mapping::internal {
namespace {

constexpr unsigned kMaxThreads = 8;  // beyond the 2-8 cores this runs on, blocks get too few

// The cores this process may run on: its CPU affinity (taskset, a cluster job's cpuset), which
// hardware_concurrency ignores: a run given one core of 64 would start 8 threads on it.
unsigned Cores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace

void ParallelFor(std::size_t n, std::size_t block,
                 const std::function<void(std::size_t begin, std::size_t end)>& body,
                 unsigned max_threads) {
  if (n == 0) return;
  block = std::max<std::size_t>(block, 1);
  const std::size_t blocks = (n + block - 1) / block;
  const unsigned cores = std::min(Cores(), kMaxThreads);
  const unsigned threads = static_cast<unsigned>(
      std::min<std::size_t>(blocks, max_threads > 0 ? std::min(max_threads, cores) : cores));
  std::atomic<std::size_t> next{0};
  const auto work = [&] {
    for (std::size_t b = next++; b < blocks; b = next++) {
      body(b * block, std::min(n, (b + 1) * block));
    }
  };
  std::vector<std::future<void>> helpers;
  try {
    for (unsigned t = 1; t < threads; ++t) helpers.push_back(std::async(std::launch::async, work));
  } catch (const std::system_error&) {  // no thread to be had: the calling one does the rest
  }
  // The caller's own share: its exception waits for the helpers (their futures' destructors) and
  // then propagates; a helper's comes from get().
  work();
  for (std::future<void>& h : helpers) h.get();
}

}  // namespace pitchlab::mapping::internal
