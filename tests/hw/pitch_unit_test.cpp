#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "pitchlab/hw/pitch_unit_driver.hpp"
#include "pitchlab/hw/pitch_unit_emulator.hpp"

namespace pitchlab::hw {
namespace {

using std::chrono::milliseconds;
constexpr double kDeg = M_PI / 180.0;
constexpr double kEncoderTolerance_rad = 2 * M_PI / 36000;  // one count

TEST(PitchProtocol, CrcIsCcittFalse) {
  const std::string check = "123456789";
  EXPECT_EQ(pitch::Crc16Ccitt(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()),
            0x29B1);
}

TEST(PitchProtocol, FramesRoundTripThroughGarbageAndCrcErrors) {
  pitch::FrameReader reader;
  std::vector<std::uint8_t> bytes = {0x00, 0xA5, 0x99};  // garbage and a false SYNC
  auto bad = pitch::Encode(pitch::MoveRequest(-12));
  bad[3] ^= 0x10;
  bytes.insert(bytes.end(), bad.begin(), bad.end());
  const auto good = pitch::Encode(pitch::EncodeStatus({pitch::kSettled, -12, -1080}));
  bytes.insert(bytes.end(), good.begin(), good.end());
  reader.Feed(bytes.data(), bytes.size());
  auto frame = reader.Next();
  ASSERT_TRUE(frame);
  Result<pitch::Status> status = pitch::DecodeStatus(*frame);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->target, -12);
  EXPECT_EQ(status->count, -1080);
  EXPECT_FALSE(reader.Next());
  EXPECT_GE(reader.crc_errors(), 1u);
}

TEST(PitchProtocol, DocumentedMoveFrameBytes) {
  const auto bytes = pitch::Encode(pitch::MoveRequest(16));
  ASSERT_EQ(bytes.size(), 7u);
  EXPECT_EQ(bytes[0], 0xA5);
  EXPECT_EQ(bytes[1], 0x03);
  EXPECT_EQ(bytes[2], 0x02);
  EXPECT_EQ(bytes[3], 0x10);
  EXPECT_EQ(bytes[4], 0x00);
}

class PitchUnitDriverTest : public ::testing::Test {
 protected:
  PitchUnitDriverConfig Config() const {
    PitchUnitDriverConfig c;
    c.device = emulator_.path();
    return c;
  }
  sensors::PitchUnitConfig unit_;
  PitchUnitEmulator emulator_{unit_};
};

TEST_F(PitchUnitDriverTest, MovesToTheNearestStepAndReadsTheEncoder) {
  PitchUnitDriver driver(Config());
  EXPECT_EQ(driver.info().step_cdeg, 45);
  Result<double> reached = driver.MoveTo(10.0 * kDeg, milliseconds(2000));
  ASSERT_TRUE(reached) << reached.error().message;
  const sensors::PitchUnitModel model(unit_);
  EXPECT_NEAR(*reached, model.StepAngle(model.StepFor(10.0 * kDeg)), kEncoderTolerance_rad);
  Result<double> encoder = driver.ReadEncoder();
  ASSERT_TRUE(encoder);
  EXPECT_NEAR(*encoder, *reached, kEncoderTolerance_rad);
}

TEST_F(PitchUnitDriverTest, TargetsBeyondTheLimitsAreClamped) {
  PitchUnitDriver driver(Config());
  Result<double> reached = driver.MoveTo(-80.0 * kDeg, milliseconds(3000));
  ASSERT_TRUE(reached) << reached.error().message;
  EXPECT_NEAR(*reached, -60.0 * kDeg, 0.45 * kDeg);
}

TEST_F(PitchUnitDriverTest, CorruptedRepliesAreRetried) {
  PitchUnitDriver driver(Config());
  for (auto kind : {FaultPlan::Kind::kFlip, FaultPlan::Kind::kDrop, FaultPlan::Kind::kDuplicate,
                    FaultPlan::Kind::kSilent, FaultPlan::Kind::kDelay}) {
    FaultPlan plan;
    plan.kind = kind;
    plan.messages = 1;
    emulator_.SetFaults(plan);
    Result<double> reached = driver.MoveTo(5.0 * kDeg, milliseconds(3000));
    ASSERT_TRUE(reached) << int(kind) << ": " << reached.error().message;
    EXPECT_NEAR(*reached, 4.95 * kDeg, kEncoderTolerance_rad);
  }
  EXPECT_GT(driver.retries(), 0u);
}

TEST_F(PitchUnitDriverTest, SilentBoardFailsWithATimeoutNamingTheDevice) {
  PitchUnitDriver driver(Config());
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kSilent;
  emulator_.SetFaults(plan);
  Result<double> reached = driver.MoveTo(5.0 * kDeg, milliseconds(1000));
  ASSERT_FALSE(reached);
  EXPECT_EQ(reached.error().code, Error::Code::kTimeout);
  EXPECT_NE(reached.error().message.find(emulator_.path()), std::string::npos);
}

TEST_F(PitchUnitDriverTest, UnpluggedBoardIsADeviceError) {
  PitchUnitDriver driver(Config());
  emulator_.Unplug();
  Result<double> reached = driver.MoveTo(5.0 * kDeg, milliseconds(1000));
  ASSERT_FALSE(reached);
  EXPECT_EQ(reached.error().code, Error::Code::kDevice);
}

TEST_F(PitchUnitDriverTest, UnplugMidMoveIsADeviceErrorNamingTheDevice) {
  PitchUnitDriver driver(Config());
  std::thread unplug([&] {
    // 0 -> -60 deg at 90 deg/s takes about 0.67 s: the board goes while the servo slews.
    std::this_thread::sleep_for(milliseconds(150));
    emulator_.Unplug();
  });
  Result<double> reached = driver.MoveTo(-60.0 * kDeg, milliseconds(5000));
  unplug.join();
  ASSERT_FALSE(reached);
  EXPECT_EQ(reached.error().code, Error::Code::kDevice);
  EXPECT_NE(reached.error().message.find(emulator_.path()), std::string::npos)
      << reached.error().message;
}

TEST_F(PitchUnitDriverTest, StepSizeMismatchThrowsNamingTheField) {
  PitchUnitDriverConfig config = Config();
  config.unit.step_deg = 0.9;
  try {
    PitchUnitDriver driver(config);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("step_deg"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pitchlab::hw
