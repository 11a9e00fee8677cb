// Ctrl-C in the drivers: a stop request (what SIGINT / SIGTERM set) ends every wait with an
// "interrupted" error instead of a retry or a timeout, and the driver's destructor then leaves
// the device safe. The flag is process-wide: each test clears it again.

#include <gtest/gtest.h>

#include <csignal>

#include <chrono>
#include <thread>

#include "pitchlab/hw/lms200_driver.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/hw/p2os_driver.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"
#include "pitchlab/hw/pitch_unit_driver.hpp"
#include "pitchlab/hw/pitch_unit_emulator.hpp"
#include "pitchlab/hw/stop_request.hpp"

namespace pitchlab::hw {
namespace {

using std::chrono::milliseconds;

class StopRequestTest : public ::testing::Test {
 protected:
  void SetUp() override { ClearStopRequest(); }
  void TearDown() override { ClearStopRequest(); }
  // Requests the stop from another thread once `ready` holds, as a signal would arrive.
  template <typename Ready>
  std::thread StopWhen(Ready ready, int signal = SIGINT) {
    return std::thread([ready, signal] {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!ready() && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(milliseconds(5));
      }
      RequestStop(signal);
    });
  }
};

TEST_F(StopRequestTest, ARealSigintSetsTheFlagAndNamesTheSignal) {
  InstallStopSignalHandlers();
  ASSERT_FALSE(StopRequested());
  ASSERT_EQ(std::raise(SIGINT), 0);  // the handler only records it: the process goes on
  EXPECT_TRUE(StopRequested());
  EXPECT_EQ(StopSignal(), SIGINT);
  EXPECT_EQ(StopExitCode(), 130);
  EXPECT_EQ(StopError("LMS200 on /dev/x").message, "LMS200 on /dev/x: interrupted by SIGINT");
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

TEST_F(StopRequestTest, AStreamingLmsWaitEndsInterruptedAndTheDeviceStopsStreaming) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Lms200DriverConfig config;
  config.device = emulator.path();
  config.lms.baud = 38400;
  config.continuous = true;
  {
    Lms200Driver driver(config);
    ASSERT_TRUE(emulator.streaming());
    ASSERT_TRUE(driver.NextLine(milliseconds(2000)));
    emulator.SetFaults({FaultPlan::Kind::kSilent});  // nothing more arrives: a long wait
    std::thread stop = StopWhen([] { return true; }, SIGTERM);
    Result<sensors::LaserLine> line = driver.NextLine(milliseconds(30000));
    stop.join();
    ASSERT_FALSE(line);
    EXPECT_EQ(line.error().code, Error::Code::kFailed);  // not kTimeout: it did not wait it out
    EXPECT_NE(line.error().message.find("interrupted by SIGTERM"), std::string::npos)
        << line.error().message;
    EXPECT_NE(line.error().message.find(emulator.path()), std::string::npos);
    emulator.SetFaults({});
  }
  // The destructor switched the output back to "on request".
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (emulator.streaming() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(5));
  }
  EXPECT_FALSE(emulator.streaming());
}

TEST_F(StopRequestTest, ADriveEndsInterruptedAndTheBaseIsLeftStoppedWithMotorsOff) {
  P2osEmulator emulator{P2osEmulatorConfig{38400}};
  P2osDriverConfig config;
  config.device = emulator.path();
  config.baud = 38400;
  {
    P2osDriver driver(config);
    std::thread stop = StopWhen([&] { return emulator.command().first > 0.0; });
    Result<sensors::Odometry> odom = driver.Drive(0.3, 0.0, 30.0);
    stop.join();
    ASSERT_FALSE(odom);
    EXPECT_EQ(odom.error().code, Error::Code::kFailed);
    EXPECT_NE(odom.error().message.find("interrupted by SIGINT"), std::string::npos)
        << odom.error().message;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (emulator.motors_enabled() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(5));
  }
  EXPECT_FALSE(emulator.motors_enabled());
  EXPECT_EQ(emulator.command(), std::make_pair(0.0, 0.0));
}

TEST_F(StopRequestTest, APitchMoveEndsInterrupted) {
  sensors::PitchUnitConfig unit;
  PitchUnitEmulator emulator{unit};
  PitchUnitDriverConfig config;
  config.device = emulator.path();
  PitchUnitDriver driver(config);
  std::thread stop = StopWhen([] { return true; });
  Result<double> reached = driver.MoveTo(-60.0 * M_PI / 180.0, milliseconds(30000));
  stop.join();
  ASSERT_FALSE(reached);
  EXPECT_EQ(reached.error().code, Error::Code::kFailed);
  EXPECT_NE(reached.error().message.find("interrupted"), std::string::npos)
      << reached.error().message;
}

TEST_F(StopRequestTest, DriverStartupStopsAtTheRequestNamingIt) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  emulator.SetFaults({FaultPlan::Kind::kSilent});  // the baud probe would take seconds
  Lms200DriverConfig config;
  config.device = emulator.path();
  RequestStop(SIGINT);
  try {
    Lms200Driver driver(config);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("interrupted by SIGINT"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pitchlab::hw
