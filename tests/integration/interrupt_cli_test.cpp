// Ctrl-C and `kill` to `pitchlab run` and `pitchlab bench`, and a disk that fills up under a run
// (issue 18): the process says what happened, removes its unfinished (hidden, staged) output, and
// exits 128 + signal, or 1 naming the file it could not write.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::Slurp;

const fs::path kYard = fs::path(PITCHLAB_SOURCE_DIR) / "tests/data/worlds/yard.xml";
// A run creates its staging folder within a second of starting (before its ground truth); on a
// loaded 2-core CI machine, allow far more.
constexpr auto kStagingAppears = std::chrono::seconds(60);

struct Ended {
  int exit_code = -1;
  std::string err;
};

class InterruptCli : public ::testing::Test {
 protected:
  // A child still running (its test failed before signalling it) would write on into dir_
  // while dir_ is removed: stop it first.
  void TearDown() override {
    for (const pid_t pid : running_) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }

  // Starts `pitchlab args...` with stderr into dir_/stderr.txt; `max_file_bytes` > 0 limits the
  // size of any file it writes (a full disk, portably: writes past it fail with EFBIG).
  pid_t Start(std::vector<std::string> args, rlim_t max_file_bytes = 0) {
    args.insert(args.begin(), PITCHLAB_CLI);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string err = (dir_ / "stderr.txt").string();
    const pid_t pid = ::fork();
    if (pid == 0) {
      const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 2);
      if (max_file_bytes > 0) {
        ::signal(SIGXFSZ, SIG_IGN);  // kept across exec: the write fails instead of killing
        const rlimit limit{max_file_bytes, max_file_bytes};
        ::setrlimit(RLIMIT_FSIZE, &limit);
      }
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    if (pid > 0) running_.push_back(pid);
    return pid;
  }
  // Waits until a hidden staging folder whose name starts with `prefix` exists under `folder`.
  static bool StagingAppears(const fs::path& folder, const std::string& prefix) {
    const auto deadline = std::chrono::steady_clock::now() + kStagingAppears;
    while (std::chrono::steady_clock::now() < deadline) {
      if (!Staging(folder, prefix).empty()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  static std::vector<std::string> Staging(const fs::path& folder, const std::string& prefix) {
    std::vector<std::string> found;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(folder, ec)) {
      const std::string name = e.path().filename().string();
      if (name.rfind(prefix, 0) == 0 && name.find(".partial") != std::string::npos)
        found.push_back(name);
    }
    return found;
  }
  Ended Wait(pid_t pid) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    running_.erase(std::remove(running_.begin(), running_.end(), pid), running_.end());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(dir_ / "stderr.txt")};
  }

  const test_support::ScopedTempDir dir_{"interrupt"};
  std::vector<pid_t> running_;
};

TEST_F(InterruptCli, RunRemovesItsStagingFolderAndSaysSoOnEitherSignal) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const fs::path out = dir_ / ("run" + std::to_string(signal));
    const pid_t pid = Start({"run", "--world", kYard.string(), "--out", out.string()});
    ASSERT_TRUE(StagingAppears(dir_.path(), "." + out.filename().string()))
        << Slurp(dir_ / "stderr.txt");
    ::kill(pid, signal);
    const Ended e = Wait(pid);
    EXPECT_EQ(e.exit_code, 128 + signal) << e.err;
    EXPECT_NE(e.err.find(signal == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM"),
              std::string::npos)
        << e.err;
    EXPECT_NE(e.err.find("removed the unfinished output folder '" + out.string() + "'"),
              std::string::npos)
        << e.err;
    EXPECT_TRUE(Staging(dir_.path(), "." + out.filename().string()).empty());
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST_F(InterruptCli, AFullDiskDuringARunNamesTheFileAndLeavesNothing) {
  const fs::path out = dir_ / "run";
  // 64 kB: less than the first stop's scan (tens of thousands of 28-byte points).
  const pid_t pid = Start({"run", "--world", kYard.string(), "--quiet", "--out", out.string()},
                          64 * 1024);
  const Ended e = Wait(pid);
  EXPECT_EQ(e.exit_code, 1) << e.err;
  EXPECT_NE(e.err.find("cannot write PCD '" + (out / "stops").string()), std::string::npos)
      << e.err;
  EXPECT_NE(e.err.find(std::strerror(EFBIG)), std::string::npos) << e.err;
  EXPECT_TRUE(Staging(dir_.path(), ".run").empty());
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(InterruptCli, AFullDiskUnderMapSaysWhyAndLeavesNothing) {
  const fs::path out = dir_ / "map";
  const fs::path scan = fs::path(PITCHLAB_SOURCE_DIR) / "tests/data/real/3dtk_corridor/scan000.3d";
  // 16 kB: less than the map's lossless file of 333 x 147 cells.
  const pid_t pid = Start({"map", scan.string(), "--out", out.string()}, 16 * 1024);
  const Ended e = Wait(pid);
  EXPECT_EQ(e.exit_code, 1) << e.err;
  EXPECT_NE(e.err.find("pitchlab map: error: "), std::string::npos) << e.err;
  EXPECT_NE(e.err.find(": cannot write: " + std::string(std::strerror(EFBIG))), std::string::npos)
      << e.err;
  EXPECT_TRUE(Staging(dir_.path(), ".map").empty());
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(InterruptCli, BenchStopsItsRunsAndLeavesNoStagingFolder) {
  const fs::path bench = dir_ / "bench";
  const pid_t pid = Start({"bench", "--worlds", kYard.string(), "--seeds", "1", "--out",
                           bench.string(), "--timeout-s", "600"});
  ASSERT_TRUE(StagingAppears(bench / "runs", ".yard-s1")) << Slurp(dir_ / "stderr.txt");
  ::kill(pid, SIGTERM);  // the bench alone, as a service manager stops it
  const Ended e = Wait(pid);
  EXPECT_EQ(e.exit_code, 128 + SIGTERM) << e.err;
  EXPECT_NE(e.err.find("interrupted by SIGTERM"), std::string::npos) << e.err;
  EXPECT_TRUE(Staging(bench / "runs", ".yard-s1").empty());
  EXPECT_FALSE(fs::exists(bench / "runs" / "yard-s1"));
  // The stopped run is no result: nothing recorded, so a resumed sweep runs it.
  EXPECT_EQ(Slurp(bench / "runs.jsonl").find("yard"), std::string::npos)
      << Slurp(bench / "runs.jsonl");
}

}  // namespace
}  // namespace pitchlab
