#include "output_paths.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "cli_args.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::apps {
namespace {

namespace fs = std::filesystem;

// Runs each test in a fresh folder as the working directory, as a user runs `pitchlab run` in a
// fresh clone, and goes back afterwards.
class OutputPaths : public ::testing::Test {
 protected:
  void SetUp() override { fs::current_path(dir_.path()); }
  void TearDown() override { fs::current_path(home_); }  // before dir_ goes
  const fs::path home_ = fs::current_path();
  const test_support::ScopedTempDir dir_{"outputpaths"};
};

TEST_F(OutputPaths, ANewFolderInAMissingRelativeFolderIsFine) {
  // `pitchlab run` with no --out on a fresh clone: runs/ does not exist yet.
  EXPECT_NO_THROW(CheckNewFolder("out", "runs/terrain-s1-20261202-145230"));
  EXPECT_NO_THROW(CheckNewFolder("out", "a/b/c/run"));
  EXPECT_NO_THROW(CheckNewFolder("out", "run"));
  EXPECT_NO_THROW(CheckNewFolder("out", "runs/x/"));
  EXPECT_FALSE(fs::exists("runs"));  // a check creates nothing
}

TEST_F(OutputPaths, AnExistingFolderOrAFileInTheWayIsRefusedByName) {
  fs::create_directories("runs/old");
  std::ofstream("file") << "x";
  try {
    CheckNewFolder("out", "runs/old");
    ADD_FAILURE() << "an existing folder was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("output folder 'runs/old' already exists"),
              std::string::npos)
        << e.what();
  }
  try {
    CheckNewFolder("out", "file/run");
    ADD_FAILURE() << "a file as the parent was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'file' is not a folder"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CheckNewFolder("out", ""), CliError);
}

TEST_F(OutputPaths, AFileNeedsItsFolder) {
  EXPECT_NO_THROW(CheckOutputFile("out", "scan.pcd"));
  try {
    CheckOutputFile("out", "missing/scan.pcd");
    ADD_FAILURE() << "a file in a missing folder was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'missing' does not exist"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pitchlab::apps
