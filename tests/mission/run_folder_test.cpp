#include "pitchlab/mission/run_folder.hpp"

#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

fs::path Scratch() {
  const fs::path dir = fs::temp_directory_path() /
                       ("pitchlab_runfolder_" + std::to_string(::getpid()) + "_" +
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(RunFolder, NothingAppearsUntilCommitAndThenEverything) {
  const fs::path dir = Scratch(), target = dir / "run1";
  {
    RunFolder folder(target);
    WriteTextFile(folder.File("stops/0/registration.json"), "{}");
    EXPECT_FALSE(fs::exists(target));
    folder.Commit();
  }
  EXPECT_TRUE(fs::exists(target / "stops/0/registration.json"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);
}

TEST(RunFolder, AFailedRunLeavesNoFolderBehind) {
  const fs::path dir = Scratch(), target = dir / "run2";
  try {
    RunFolder folder(target);
    WriteTextFile(folder.File("metrics.json"), "{}");
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 0);
}

TEST(RunFolder, RefusesToOverwriteAnExistingRun) {
  const fs::path dir = Scratch();
  fs::create_directories(dir / "run3");
  EXPECT_THROW(RunFolder{dir / "run3"}, std::runtime_error);
}

}  // namespace
}  // namespace pitchlab::mission
