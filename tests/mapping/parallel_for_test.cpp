#include "pitchlab/mapping/parallel_for.hpp"
#include "pitchlab/sensors/allowed_cores.hpp"

#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace pitchlab::mapping {
namespace {

// Every item is visited exactly once, whatever the block size and thread count.
TEST(ParallelFor, VisitsEveryItemOnce) {
  for (const std::size_t n : {0u, 1u, 7u, 256u, 1000u}) {
    for (const std::size_t block : {1u, 3u, 256u, 5000u}) {
      for (const unsigned threads : {0u, 1u, 2u, 8u}) {
        std::vector<std::atomic<int>> visits(n);
        ParallelFor(
            n, block,
            [&](std::size_t begin, std::size_t end) {
              ASSERT_LE(end - begin, block);
              for (std::size_t i = begin; i < end; ++i) ++visits[i];
            },
            threads);
        for (std::size_t i = 0; i < n; ++i) {
          ASSERT_EQ(visits[i].load(), 1) << "n " << n << " block " << block << " item " << i;
        }
      }
    }
  }
}

TEST(ParallelFor, OneThreadIsTheCallerAlone) {
  std::set<std::thread::id> ids;
  ParallelFor(
      100, 1, [&](std::size_t, std::size_t) { ids.insert(std::this_thread::get_id()); }, 1);
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

TEST(ParallelFor, UsesMoreThanOneThreadWhereTheMachineHasThem) {
  if (sensors::AllowedCores() < 2) GTEST_SKIP() << "one core";
  std::mutex mutex;
  std::set<std::thread::id> ids;
  std::atomic<int> arrived{0};
  // Each of the two blocks waits (bounded) until the other started: only two threads pass.
  ParallelFor(
      2, 1,
      [&](std::size_t, std::size_t) {
        {
          std::lock_guard<std::mutex> lock(mutex);
          ids.insert(std::this_thread::get_id());
        }
        ++arrived;
        for (int i = 0; i < 2000 && arrived.load() < 2; ++i) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
      },
      2);
  EXPECT_EQ(ids.size(), 2u);
}

// Within a SerialLoops' life the thread's loops run on it alone (they nest); after it, as before.
TEST(ParallelFor, SerialLoopsKeepTheThreadsLoopsOnItself) {
  // Each of the two blocks waits (up to `wait_ms`) until the other started.
  const auto threads_used = [](int wait_ms) {
    std::mutex mutex;
    std::set<std::thread::id> ids;
    std::atomic<int> arrived{0};
    ParallelFor(2, 1, [&](std::size_t, std::size_t) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        ids.insert(std::this_thread::get_id());
      }
      ++arrived;
      for (int i = 0; i < wait_ms && arrived.load() < 2; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
    return ids;
  };
  const std::set<std::thread::id> me{std::this_thread::get_id()};
  {
    const SerialLoops alone;
    EXPECT_EQ(threads_used(20), me);
    {
      const SerialLoops nested;
      EXPECT_EQ(threads_used(20), me);
    }
    EXPECT_EQ(threads_used(20), me);
  }
  if (sensors::AllowedCores() < 2) GTEST_SKIP() << "one core";
  EXPECT_EQ(threads_used(2000).size(), 2u);
}

// A process allowed one core (taskset, a cluster job's cpuset) runs its loops on the caller alone,
// however many cores the machine has.
TEST(ParallelFor, KeepsToTheCoresTheProcessIsAllowed) {
  cpu_set_t before;
  ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
  int first = 0;
  while (!CPU_ISSET(first, &before)) ++first;
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
  std::set<std::thread::id> ids;
  ParallelFor(64, 1, [&](std::size_t, std::size_t) { ids.insert(std::this_thread::get_id()); });
  ASSERT_EQ(sched_setaffinity(0, sizeof before, &before), 0);
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

// A block's exception reaches the caller, after every thread stopped (none touches `visits`
// once ParallelFor returned: it would be a use after scope under ASan).
TEST(ParallelFor, ABodysExceptionReachesTheCaller) {
  for (const unsigned threads : {1u, 2u, 4u}) {
    std::vector<int> visits(64, 0);
    EXPECT_THROW(ParallelFor(
                     64, 1,
                     [&](std::size_t begin, std::size_t) {
                       visits[begin] = 1;
                       if (begin == 5) throw std::runtime_error("item 5");
                     },
                     threads),
                 std::runtime_error);
    EXPECT_EQ(visits[5], 1);
  }
}

// Loops from several threads at once, and a loop inside a loop's body, share the helper threads
// and each visits its own items once (none waits on a helper busy with another's).
TEST(ParallelFor, ConcurrentAndNestedLoopsEachFinish) {
  constexpr std::size_t kOuter = 16, kInner = 300;
  std::vector<std::thread> callers;
  std::vector<std::vector<std::atomic<int>>> visits(4);
  for (auto& v : visits) v = std::vector<std::atomic<int>>(kOuter * kInner);
  for (std::size_t c = 0; c < visits.size(); ++c) {
    callers.emplace_back([&visits, c] {
      ParallelFor(kOuter, 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t o = begin; o < end; ++o) {
          ParallelFor(kInner, 7, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) ++visits[c][o * kInner + i];
          });
        }
      });
    });
  }
  for (std::thread& t : callers) t.join();
  for (const auto& v : visits) {
    for (const auto& x : v) ASSERT_EQ(x.load(), 1);
  }
}

}  // namespace
}  // namespace pitchlab::mapping
