#pragma once
// A test's scratch folder in the temp directory that goes when the test does, pass or fail: a run
// of the suite leaves the temp directory as it found it (hundreds of folders were left before).

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace pitchlab::test_support {

/// An empty folder <tmp>/pitchlab_<tag>_<pid>_<suite>.<test>_<n>, made on construction and removed
/// with all it holds on destruction. The pid keeps apart the test processes CTest runs in
/// parallel, the test's name says whose the folder is, and n keeps apart those of one process.
class ScopedTempDir {
 public:
  explicit ScopedTempDir(const std::string& tag)
      : path_(std::filesystem::temp_directory_path() / Name(tag)) {
    std::filesystem::remove_all(path_);  // an earlier process with the same pid may have left it
    std::filesystem::create_directories(path_);
  }
  ~ScopedTempDir() {
    std::error_code ignored;  // never throw from a destructor; a leftover is no test's failure
    std::filesystem::remove_all(path_, ignored);
  }
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& name) const { return path_ / name; }

 private:
  static std::string Name(const std::string& tag) {
    static std::atomic<int> made{0};
    const ::testing::UnitTest& unit = *::testing::UnitTest::GetInstance();
    std::string test;  // empty outside a test and its suite (a static's constructor)
    if (const ::testing::TestInfo* info = unit.current_test_info()) {
      test = std::string(info->test_suite_name()) + "." + info->name();
    } else if (const ::testing::TestSuite* suite = unit.current_test_suite()) {
      test = suite->name();  // in SetUpTestSuite
    }
    // A parameterised test's name holds '/': one folder, not a nest that removal would leave.
    for (char& c : test) c = c == '/' ? '_' : c;
    constexpr std::size_t kMaxTestChars = 160;  // the whole name within NAME_MAX (255)
    return "pitchlab_" + tag + "_" + std::to_string(::getpid()) + "_" +
           test.substr(0, kMaxTestChars) + "_" + std::to_string(made++);
  }

  std::filesystem::path path_;
};

}  // namespace pitchlab::test_support
