// Where an emulator's device path lives when none is given: a folder of its own under TMPDIR,
// gone with the device, and gone too when the device cannot be made.

#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/hw/pitch_unit_emulator.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::hw {
namespace {

namespace fs = std::filesystem;

// TMPDIR set to `dir` for the scope, and back as it was.
class ScopedTmpdir {
 public:
  explicit ScopedTmpdir(const fs::path& dir) {
    if (const char* old = std::getenv("TMPDIR")) old_ = old;
    ::setenv("TMPDIR", dir.c_str(), 1);
  }
  ~ScopedTmpdir() { old_ ? ::setenv("TMPDIR", old_->c_str(), 1) : ::unsetenv("TMPDIR"); }

 private:
  std::optional<std::string> old_;
};

int Entries(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(EmulatedDeviceFolder, LivesUnderTmpdirAndGoesWithTheDevice) {
  const test_support::ScopedTempDir dir("emulated_device");
  const ScopedTmpdir tmpdir(dir.path());
  {
    const PitchUnitEmulator board(sensors::PitchUnitConfig{});
    const fs::path link = board.path();
    EXPECT_EQ(link.parent_path().parent_path(), dir.path()) << link;
    EXPECT_EQ(link.parent_path().filename().string().rfind("pitchlab-hw-", 0), 0u) << link;
    EXPECT_TRUE(fs::is_symlink(link)) << link;
  }
  EXPECT_EQ(Entries(dir.path()), 0);
}

// One file descriptor left where the pseudo-terminal needs two (the soft limit one above the
// lowest free number): the constructor throws naming the emulator, and the folder it had made is
// gone. A device is made and dropped first: UBSan's vptr check validates a type it has not seen
// by reading /proc/self/maps, which it cannot open without a descriptor, and would report the
// device as having an invalid vptr; seen once, the answer is cached.
TEST(EmulatedDeviceFolder, ADeviceThatCannotBeMadeLeavesNoFolder) {
  const test_support::ScopedTempDir dir("emulated_device");
  const ScopedTmpdir tmpdir(dir.path());
  { const PitchUnitEmulator seen(sensors::PitchUnitConfig{}); }
  rlimit before{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &before), 0);
  const int lowest_free = ::dup(0);
  ASSERT_GE(lowest_free, 0);
  ::close(lowest_free);
  rlimit one = before;
  one.rlim_cur = static_cast<rlim_t>(lowest_free) + 1;
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &one), 0);
  std::exception_ptr failure;  // read once the limit is back (UBSan: the same as above)
  try {
    const PitchUnitEmulator board(sensors::PitchUnitConfig{});
  } catch (...) {
    failure = std::current_exception();
  }
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &before), 0);
  std::string message;
  try {
    if (failure) std::rethrow_exception(failure);
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("openpty"), std::string::npos) << message;
  EXPECT_EQ(Entries(dir.path()), 0);
}

}  // namespace
}  // namespace pitchlab::hw
