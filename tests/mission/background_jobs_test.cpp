#include "background_jobs.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::mission {
namespace {

TEST(BackgroundJobs, RunsJobsInOrderOnAnotherThread) {
  std::vector<int> order;
  std::thread::id ran_on;
  BackgroundJobs jobs;
  for (int i = 0; i < 5; ++i) {
    jobs.Post([&order, &ran_on, i] {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      order.push_back(i);
      ran_on = std::this_thread::get_id();
    });
  }
  jobs.Wait();
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_NE(ran_on, std::this_thread::get_id());
  jobs.Wait();  // nothing queued: returns at once
}

int ThisThreadsNice() {
  errno = 0;
  return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
}

// The side work yields the cores to the mission (background_jobs.cpp): its thread runs nicer than
// the one that posts, which keeps its own priority.
TEST(BackgroundJobs, JobsRunAtALowerPriorityThanTheMission) {
  const int mission_nice = ThisThreadsNice();
  if (mission_nice >= 19) GTEST_SKIP() << "the test runs at the lowest priority already";
  int job_nice = mission_nice;
  BackgroundJobs jobs;
  jobs.Post([&job_nice] { job_nice = ThisThreadsNice(); });
  jobs.Wait();
  EXPECT_GT(job_nice, mission_nice);
  EXPECT_EQ(ThisThreadsNice(), mission_nice);
}

TEST(BackgroundJobs, AFailureReachesWaitAndLaterPostsAndDropsTheRest) {
  BackgroundJobs jobs;
  std::atomic<bool> later_ran{false};
  jobs.Post([] { throw std::runtime_error("disk full"); });
  jobs.Post([&] { later_ran = true; });
  try {
    jobs.Wait();
    ADD_FAILURE() << "Wait did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "disk full");
  }
  EXPECT_THROW(jobs.Post([] {}), std::runtime_error);
  EXPECT_FALSE(later_ran);
}

TEST(BackgroundJobs, DestructionDropsJobsNotStarted) {
  std::atomic<int> ran{0};
  {
    BackgroundJobs jobs;
    jobs.Post([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      ++ran;
    });
    for (int i = 0; i < 10; ++i) jobs.Post([&] { ++ran; });
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the first is running
  }
  EXPECT_EQ(ran.load(), 1);
}

// The jobs' CPU time is theirs: a foreground stopwatch leaves it out, a whole-process one counts
// it.
TEST(BackgroundJobs, TheirCpuTimeIsLeftOutOfForegroundStopwatches) {
  const sensors::Stopwatch foreground(sensors::CpuOf::kForeground);
  const sensors::Stopwatch process(sensors::CpuOf::kProcess);
  double job_cpu_s = 0;
  {
    BackgroundJobs jobs;
    jobs.Post([&] {
      const double start = sensors::ThreadCpuSeconds();
      volatile double sink = 0;
      while (sensors::ThreadCpuSeconds() - start < 0.2) sink = sink + 1;
      job_cpu_s = sensors::ThreadCpuSeconds() - start;
    });
    jobs.Wait();
  }  // the thread ended: its time stays out
  EXPECT_GE(job_cpu_s, 0.2);
  EXPECT_GE(process.Read().cpu_s, 0.2);
  EXPECT_LT(foreground.Read().cpu_s, 0.1);
}

}  // namespace
}  // namespace pitchlab::mission
