#include "pitchlab/mission/run_folder.hpp"

#include <filesystem>

#include <gtest/gtest.h>

#include "scoped_temp_dir.hpp"

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

using test_support::ScopedTempDir;

TEST(RunFolder, NothingAppearsUntilCommitAndThenEverything) {
  const ScopedTempDir dir("runfolder");
  const fs::path target = dir / "run1";
  {
    RunFolder folder(target);
    WriteTextFile(folder.File("stops/0/registration.json"), "{}");
    EXPECT_FALSE(fs::exists(target));
    folder.Commit();
  }
  EXPECT_TRUE(fs::exists(target / "stops/0/registration.json"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1);
}

TEST(RunFolder, AFailedRunLeavesNoFolderBehind) {
  const ScopedTempDir dir("runfolder");
  const fs::path target = dir / "run2";
  try {
    RunFolder folder(target);
    WriteTextFile(folder.File("metrics.json"), "{}");
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 0);
}

TEST(RunFolder, RefusesToOverwriteAnExistingRun) {
  const ScopedTempDir dir("runfolder");
  fs::create_directories(dir / "run3");
  EXPECT_THROW(RunFolder{dir / "run3"}, std::runtime_error);
}

}  // namespace
}  // namespace pitchlab::mission
