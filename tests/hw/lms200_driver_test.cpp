// The LMS200 driver against the emulated device on a pty, at 38400 baud (a pty cannot do 500k).

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "pitchlab/hw/lms200_driver.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"

namespace pitchlab::hw {
namespace {

using std::chrono::milliseconds;
constexpr milliseconds kLineTimeout{2000};

sensors::LaserLine ExpectedWall(const sensors::Lms200Config& config, double wall_m) {
  sensors::Lms200Config quiet = config;
  quiet.noise_sigma_m = 0.0;
  sensors::Lms200Model model(quiet);
  std::vector<float> ranges(std::size_t(model.readings()));
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    const double c = std::cos(model.angle_min_rad() + double(i) * model.angle_increment_rad());
    ranges[i] = c > 0.05 ? float(wall_m / c) : INFINITY;
  }
  sensors::LaserLine line;
  model.Measure(ranges.data(), nullptr, nullptr, line);
  return line;
}

void ExpectSameReadings(const sensors::LaserLine& got, const sensors::LaserLine& want) {
  ASSERT_EQ(got.ranges_m.size(), want.ranges_m.size());
  for (std::size_t i = 0; i < got.ranges_m.size(); ++i) {
    ASSERT_EQ(got.status[i], want.status[i]) << "reading " << i;
    if (want.status[i] == sensors::ReadingStatus::kValid) {
      ASSERT_NEAR(got.ranges_m[i], want.ranges_m[i], 1e-6) << "reading " << i;
    } else {
      ASSERT_TRUE(std::isnan(got.ranges_m[i])) << "reading " << i;
    }
  }
}

class Lms200DriverTest : public ::testing::Test {
 protected:
  Lms200DriverConfig DriverConfig() const {
    Lms200DriverConfig c;
    c.device = emulator_.path();
    c.lms.baud = 38400;
    // The driver's default: a loaded 2-core machine has stalled the emulator's reply past two
    // 300 ms waits at 9600 baud (fresh-clone test run, all rates unanswered).
    c.reply_timeout_ms = Lms200DriverConfig{}.reply_timeout_ms;
    return c;
  }
  Lms200Emulator emulator_{Lms200EmulatorConfig{}};
};

TEST_F(Lms200DriverTest, InitialisesAtPowerOnRateAndSwitchesTo38400) {
  Lms200Driver driver(DriverConfig());
  EXPECT_EQ(emulator_.baud(), 38400);
  EXPECT_EQ(driver.type(), "LMS200;30106");
}

TEST_F(Lms200DriverTest, SingleScanMatchesTheDeviceReadings) {
  Lms200Driver driver(DriverConfig());
  Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
  ASSERT_TRUE(line) << line.error().message;
  EXPECT_EQ(line->ranges_m.size(), 361u);
  EXPECT_NEAR(line->angle_min_rad, -M_PI / 2, 1e-12);
  EXPECT_NEAR(line->angle_increment_rad, 0.5 * M_PI / 180, 1e-12);
  ExpectSameReadings(*line, ExpectedWall(DriverConfig().lms, 3.0));
  EXPECT_EQ(driver.stats().reader.crc_errors, 0u);
}

TEST_F(Lms200DriverTest, SetsVariantAndMillimetreMode) {
  Lms200DriverConfig config = DriverConfig();
  config.lms.fov_deg = 100;
  config.lms.resolution_deg = 0.25;
  config.lms.range_mode = sensors::Lms200RangeMode::kMm;
  Lms200Driver driver(config);
  EXPECT_EQ(emulator_.current().fov_deg, 100);
  EXPECT_EQ(emulator_.current().resolution_deg, 0.25);
  EXPECT_EQ(emulator_.current().range_mode, sensors::Lms200RangeMode::kMm);
  Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
  ASSERT_TRUE(line) << line.error().message;
  EXPECT_EQ(line->ranges_m.size(), 401u);
  ExpectSameReadings(*line, ExpectedWall(config.lms, 3.0));
}

TEST(Lms200DriverSource, SpecialCodesReachTheLineAsFlagsNeverAsZero) {
  Lms200Emulator emulator(Lms200EmulatorConfig{}, [](const sensors::Lms200Config& c) {
    sensors::LaserLine line;
    const std::size_t n = std::size_t(sensors::Lms200Model(c).readings());
    line.ranges_m.assign(n, 1.25f);
    line.status.assign(n, sensors::ReadingStatus::kValid);
    line.status[0] = sensors::ReadingStatus::kNoReturn;
    line.status[1] = sensors::ReadingStatus::kDazzled;
    line.status[2] = sensors::ReadingStatus::kOverRange;
    return line;
  });
  Lms200DriverConfig config;
  config.device = emulator.path();
  config.lms.baud = 38400;
  Lms200Driver driver(config);
  Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
  ASSERT_TRUE(line) << line.error().message;
  EXPECT_EQ(line->status[0], sensors::ReadingStatus::kNoReturn);
  EXPECT_EQ(line->status[1], sensors::ReadingStatus::kDazzled);
  EXPECT_EQ(line->status[2], sensors::ReadingStatus::kOverRange);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(std::isnan(line->ranges_m[i]));
  EXPECT_FLOAT_EQ(line->ranges_m[3], 1.25f);
}

TEST_F(Lms200DriverTest, ContinuousOutputDeliversConsecutiveLines) {
  Lms200DriverConfig config = DriverConfig();
  config.continuous = true;
  Lms200Driver driver(config);
  double last_stamp = -1e9;
  for (int i = 0; i < 3; ++i) {
    Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
    ASSERT_TRUE(line) << line.error().message;
    ExpectSameReadings(*line, ExpectedWall(config.lms, 3.0));
    EXPECT_GT(line->stamp_s, last_stamp);
    last_stamp = line->stamp_s;
  }
}

// Faults on the device's output: the driver retries and hands on only lines that passed.
struct FaultCase {
  const char* name;
  FaultPlan::Kind kind;
  int messages;
};

class Lms200FaultTest : public Lms200DriverTest, public ::testing::WithParamInterface<FaultCase> {};

TEST_P(Lms200FaultTest, DriverRecoversAndNeverHandsOnACorruptedLine) {
  Lms200Driver driver(DriverConfig());
  FaultPlan plan;
  plan.kind = GetParam().kind;
  plan.messages = GetParam().messages;
  plan.seed = 7;
  emulator_.SetFaults(plan);
  const sensors::LaserLine expected = ExpectedWall(DriverConfig().lms, 3.0);
  for (int i = 0; i < 3; ++i) {
    Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
    ASSERT_TRUE(line) << GetParam().name << ": " << line.error().message;
    ExpectSameReadings(*line, expected);
  }
  EXPECT_GT(emulator_.stats().faults, 0u);
  if (GetParam().kind != FaultPlan::Kind::kDelay) EXPECT_GT(driver.stats().retries, 0u);
}

INSTANTIATE_TEST_SUITE_P(Faults, Lms200FaultTest,
                         ::testing::Values(FaultCase{"drop", FaultPlan::Kind::kDrop, 2},
                                           FaultCase{"flip", FaultPlan::Kind::kFlip, 2},
                                           FaultCase{"duplicate", FaultPlan::Kind::kDuplicate, 2},
                                           FaultCase{"delay", FaultPlan::Kind::kDelay, 2},
                                           FaultCase{"silent", FaultPlan::Kind::kSilent, 2}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST_F(Lms200DriverTest, RandomBitFlipsNeverReachTheLine) {
  Lms200Driver driver(DriverConfig());
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kFlip;
  plan.probability = 0.3;
  plan.seed = 11;
  emulator_.SetFaults(plan);
  const sensors::LaserLine expected = ExpectedWall(DriverConfig().lms, 3.0);
  int good = 0;
  for (int i = 0; i < 10; ++i) {
    Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
    if (!line) continue;  // allowed to fail, never to lie
    ExpectSameReadings(*line, expected);
    ++good;
  }
  EXPECT_GE(good, 8);
  EXPECT_GT(driver.stats().reader.crc_errors + driver.stats().reader.garbage_bytes, 0u);
}

TEST_F(Lms200DriverTest, SilentDeviceGivesATimeoutNamingTheDevice) {
  Lms200Driver driver(DriverConfig());
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kSilent;
  emulator_.SetFaults(plan);
  const auto start = std::chrono::steady_clock::now();
  Result<sensors::LaserLine> line = driver.NextLine(milliseconds(800));
  ASSERT_FALSE(line);
  EXPECT_EQ(line.error().code, Error::Code::kTimeout);
  EXPECT_NE(line.error().message.find(emulator_.path()), std::string::npos);
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(1500));
}

TEST_F(Lms200DriverTest, UnplugMidScanStopsWithAClearDeviceError) {
  Lms200Driver driver(DriverConfig());
  std::thread unplug([&] {
    std::this_thread::sleep_for(milliseconds(80));  // the reply is on the wire by now
    emulator_.Unplug();
  });
  Result<sensors::LaserLine> line = driver.NextLine(kLineTimeout);
  unplug.join();
  ASSERT_FALSE(line);
  EXPECT_EQ(line.error().code, Error::Code::kDevice);
  EXPECT_NE(line.error().message.find(emulator_.path()), std::string::npos);
}

TEST_F(Lms200DriverTest, ReplugIsRecoveredByReconnecting) {
  Lms200Driver driver(DriverConfig());
  std::thread cycle([&] {
    std::this_thread::sleep_for(milliseconds(80));
    emulator_.Unplug();
    std::this_thread::sleep_for(milliseconds(100));
    emulator_.Replug();  // power cycle: back at 9600 baud
  });
  Result<sensors::LaserLine> line = driver.NextLine(milliseconds(5000));
  cycle.join();
  ASSERT_TRUE(line) << line.error().message;
  ExpectSameReadings(*line, ExpectedWall(DriverConfig().lms, 3.0));
  EXPECT_EQ(driver.stats().reconnects, 1u);
  EXPECT_EQ(emulator_.baud(), 38400);
}

TEST(Lms200DriverStartup, MissingDeviceThrowsNamingIt) {
  Lms200DriverConfig config;
  config.device = "/nonexistent/ttyLMS";
  try {
    Lms200Driver driver(config);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/ttyLMS"), std::string::npos);
  }
}

TEST(Lms200DriverStartup, DeviceThatNeverAnswersThrowsNamingIt) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kSilent;
  emulator.SetFaults(plan);
  Lms200DriverConfig config;
  config.device = emulator.path();
  config.reply_timeout_ms = 100;
  config.retries = 1;
  try {
    Lms200Driver driver(config);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(emulator.path()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no answer"), std::string::npos) << e.what();
  }
}

TEST(Lms200DriverConfig, InvalidFieldsThrowNamingTheField) {
  Lms200DriverConfig config;
  EXPECT_THROW(config.Validate(), std::invalid_argument);  // no device
  config.device = "/dev/null";
  config.lms.baud = 115200;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config.lms.baud = 38400;
  config.retries = 0;
  try {
    config.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("retries"), std::string::npos);
  }
}

}  // namespace
}  // namespace pitchlab::hw
