#include "pitchlab/mission/cleanup_registry.hpp"

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

// RunCleanups marks the whole process interrupted (WaitIfInterrupted blocks from then on), so each
// case runs in a child process of its own and reports by its exit code.
[[noreturn]] void Finish(bool ok, const std::string& why) {
  if (!ok) std::fprintf(stderr, "%s\n", why.c_str());
  std::exit(ok ? 0 : 1);
}

// Four cleanups, one unregistered, one reporting nothing removed, one without a name.
[[noreturn]] void RunFourCleanupsAndCheck() {
  std::vector<std::string> order;
  RegisterCleanup([&](int) { return order.push_back("a"), true; }, "folder a");
  const int b = RegisterCleanup([&](int) { return order.push_back("b"), true; }, "folder b");
  RegisterCleanup([&](int) { return order.push_back("c"), false; }, "folder c");
  RegisterCleanup([&](int s) { return order.push_back(std::to_string(s)), true; }, "");
  UnregisterCleanup(b);  // committed by its owner: not run
  const std::vector<std::string> removed = RunCleanups(SIGTERM);
  const std::vector<std::string> want_order = {std::to_string(SIGTERM), "c", "a"};
  Finish(order == want_order && removed == std::vector<std::string>{"folder a"},
         "ran " + std::to_string(order.size()) + " cleanups, reported " +
             std::to_string(removed.size()));
}

TEST(CleanupRegistry, RunsTheRegisteredCleanupsNewestFirstAndSaysWhatTheyRemoved) {
  EXPECT_EXIT(RunFourCleanupsAndCheck(), ::testing::ExitedWithCode(0), "");
}

TEST(CleanupRegistry, WaitIfInterruptedReturnsAtOnceWithoutAnInterruption) {
  WaitIfInterrupted();  // would block for good once RunCleanups had run in this process
  SUCCEED();
}

}  // namespace
}  // namespace pitchlab::mission
