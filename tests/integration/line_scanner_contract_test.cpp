// The LineScanner contract (STYLE.md "Tests"): the same checks against the simulated LMS200
// (sim::SimLineScanner in a tiny wall world) and the serial driver (hw::Lms200Driver on an
// emulated device at 38400 baud). Whatever the mission gets from one it gets from the other.

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/hw/lms200_driver.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/sensors/scan_source.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab {
namespace {

using std::chrono::milliseconds;
constexpr double kDeg = M_PI / 180.0;
constexpr milliseconds kLineTimeout{2000};
// sigma 5 mm noise (4 sigma), 1 cm quantization (half a unit), servo sag at rest.
constexpr double kRangeTolerance_m = 4 * 0.005 + 0.005 + 0.005;
constexpr double kMeanErrorBound_m = 0.006;  // over ~180 beams: no bias beyond quantization
constexpr double kWallHalfAngle_deg = 45.0;  // beams within this of straight ahead hit the wall
constexpr milliseconds kTooShort{1};         // far below one line period (13 ms + transfer)
constexpr milliseconds kTimeoutSlack{250};   // a timed-out call returns within this of its timeout

// A wall whose face is at x = 3 m, y = -5 .. 5 m, on a floor that ends 6 m out: beams beyond
// about 60 deg pass the wall's ends and see nothing.
constexpr char kWallWorld[] = R"(
<mujoco model="contract_wall">
  <worldbody>
    <geom name="floor" type="box" pos="0 0 -0.05" size="6 6 0.05"/>
    <geom name="wall" type="box" pos="3.05 0 1" size="0.05 5 1"/>
  </worldbody>
</mujoco>)";

/// One LineScanner under test with what it should see straight ahead.
class ScannerUnderTest {
 public:
  virtual ~ScannerUnderTest() = default;
  virtual sensors::LineScanner& scanner() = 0;
  /// True range of the wall for the beam at `theta_rad` [m].
  virtual double WallRange(double theta_rad) const = 0;
  /// Makes the device stop answering; false when the backend has no such failure.
  virtual bool Silence() { return false; }
};

class SimScanner final : public ScannerUnderTest {
 public:
  SimScanner() {
    sim::SimRigConfig config;
    rig_ = sim::SimRig::FromString(kWallWorld, "/tmp", config);
    if (Result<Eigen::Isometry3d> placed = rig_->PlaceRobot(0.0, 0.0, 0.0); !placed) {
      throw std::runtime_error(placed.error().message);
    }
    T_world_laser_ = rig_->sim().T_world_laser();
  }
  sensors::LineScanner& scanner() override { return rig_->scanner(); }
  double WallRange(double theta_rad) const override {
    const Eigen::Vector3d d =
        T_world_laser_.linear() * Eigen::Vector3d(std::cos(theta_rad), std::sin(theta_rad), 0);
    return (3.0 - T_world_laser_.translation().x()) / d.x();
  }

 private:
  std::unique_ptr<sim::SimRig> rig_;
  Eigen::Isometry3d T_world_laser_;
};

class DriverOnEmulator final : public ScannerUnderTest {
 public:
  DriverOnEmulator() {
    hw::Lms200DriverConfig config;
    config.device = emulator_.path();
    config.lms.baud = 38400;  // a pty cannot do 500k
    config.reply_timeout_ms = 300;
    driver_ = std::make_unique<hw::Lms200Driver>(config);
  }
  sensors::LineScanner& scanner() override { return *driver_; }
  double WallRange(double theta_rad) const override { return kWall_m / std::cos(theta_rad); }
  bool Silence() override {
    hw::FaultPlan silent;
    silent.kind = hw::FaultPlan::Kind::kSilent;
    emulator_.SetFaults(silent);
    return true;
  }

 private:
  static constexpr double kWall_m = 3.0;
  hw::Lms200Emulator emulator_{[] {
    hw::Lms200EmulatorConfig c;
    c.flat_wall_m = kWall_m;
    return c;
  }()};
  std::unique_ptr<hw::Lms200Driver> driver_;
};

struct Backend {
  std::string name;
  std::function<std::unique_ptr<ScannerUnderTest>()> make;
};
void PrintTo(const Backend& backend, std::ostream* os) { *os << backend.name; }

class LineScannerContract : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override { under_test_ = GetParam().make(); }
  sensors::LineScanner& scanner() { return under_test_->scanner(); }
  std::unique_ptr<ScannerUnderTest> under_test_;
};

INSTANTIATE_TEST_SUITE_P(
    SimAndHw, LineScannerContract,
    ::testing::Values(Backend{"SimLineScanner", [] { return std::make_unique<SimScanner>(); }},
                      Backend{"Lms200DriverOnEmulator",
                              [] { return std::make_unique<DriverOnEmulator>(); }}),
    [](const auto& info) { return info.param.name; });

TEST_P(LineScannerContract, ALineHasTheVariantsReadingsAndAngles) {
  Result<sensors::LaserLine> line = scanner().NextLine(kLineTimeout);
  ASSERT_TRUE(line) << line.error().message;
  EXPECT_EQ(line->ranges_m.size(), 361u);  // 180 deg at 0.5 deg
  EXPECT_EQ(line->status.size(), line->ranges_m.size());
  EXPECT_NEAR(line->angle_min_rad, -90.0 * kDeg, 1e-12);
  EXPECT_NEAR(line->angle_increment_rad, 0.5 * kDeg, 1e-12);
  EXPECT_EQ(line->pitch_rad, 0.0);  // the caller fills it from the encoder
}

TEST_P(LineScannerContract, AWallAheadIsMeasuredWithinNoise) {
  Result<sensors::LaserLine> line = scanner().NextLine(kLineTimeout);
  ASSERT_TRUE(line) << line.error().message;
  double sum_error = 0;
  int beams = 0;
  for (std::size_t i = 0; i < line->ranges_m.size(); ++i) {
    const double theta = line->angle_min_rad + double(i) * line->angle_increment_rad;
    if (std::abs(theta) > kWallHalfAngle_deg * kDeg) continue;
    ASSERT_EQ(line->status[i], sensors::ReadingStatus::kValid) << "beam " << i;
    const double error = line->ranges_m[i] - under_test_->WallRange(theta);
    EXPECT_LT(std::abs(error), kRangeTolerance_m) << "beam " << i;
    sum_error += error;
    ++beams;
  }
  EXPECT_EQ(beams, 181);
  EXPECT_LT(std::abs(sum_error / beams), kMeanErrorBound_m);
}

TEST_P(LineScannerContract, FlaggedReadingsAreNaNNeverZeroMetres) {
  Result<sensors::LaserLine> line = scanner().NextLine(kLineTimeout);
  ASSERT_TRUE(line) << line.error().message;
  int flagged = 0;
  for (std::size_t i = 0; i < line->ranges_m.size(); ++i) {
    if (line->status[i] == sensors::ReadingStatus::kValid) {
      EXPECT_TRUE(std::isfinite(line->ranges_m[i]) && line->ranges_m[i] > 0) << "beam " << i;
    } else {
      EXPECT_TRUE(std::isnan(line->ranges_m[i])) << "beam " << i;
      ++flagged;
    }
  }
  // The beams along the wall (+-90 deg) see nothing: flagged, not 0 m.
  EXPECT_NE(line->status.front(), sensors::ReadingStatus::kValid);
  EXPECT_NE(line->status.back(), sensors::ReadingStatus::kValid);
  EXPECT_GE(flagged, 2);
}

TEST_P(LineScannerContract, StampsIncreaseFromLineToLine) {
  Result<sensors::LaserLine> first = scanner().NextLine(kLineTimeout);
  Result<sensors::LaserLine> second = scanner().NextLine(kLineTimeout);
  ASSERT_TRUE(first && second);
  EXPECT_GT(second->stamp_s, first->stamp_s);
}

TEST_P(LineScannerContract, ATimeoutShorterThanALineIsAKTimeoutAndTheNextLineIsGood) {
  const auto start = std::chrono::steady_clock::now();
  Result<sensors::LaserLine> line = scanner().NextLine(kTooShort);
  const auto took = std::chrono::steady_clock::now() - start;
  ASSERT_FALSE(line);
  EXPECT_EQ(line.error().code, Error::Code::kTimeout) << line.error().message;
  EXPECT_LT(took, kTooShort + kTimeoutSlack);
  Result<sensors::LaserLine> next = scanner().NextLine(kLineTimeout);
  ASSERT_TRUE(next) << next.error().message;
  EXPECT_EQ(next->ranges_m.size(), 361u);
}

TEST_P(LineScannerContract, ASilentDeviceIsAKTimeoutWithinTheTimeout) {
  if (!under_test_->Silence()) GTEST_SKIP() << GetParam().name << " cannot go silent";
  constexpr milliseconds kTimeout{600};
  const auto start = std::chrono::steady_clock::now();
  Result<sensors::LaserLine> line = scanner().NextLine(kTimeout);
  const auto took = std::chrono::steady_clock::now() - start;
  ASSERT_FALSE(line);
  EXPECT_EQ(line.error().code, Error::Code::kTimeout) << line.error().message;
  EXPECT_LT(took, kTimeout + kTimeoutSlack);
}

}  // namespace
}  // namespace pitchlab
