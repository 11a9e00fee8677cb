#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <utility>

#include "pitchlab/hw/p2os_driver.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"

namespace pitchlab::hw {
namespace {

TEST(P2osProtocol, ChecksumOfTheSync0Packet) {
  // SYNC0 on the wire: FA FB 03 00 00 00.
  EXPECT_EQ(p2os::CommandPacket(p2os::kSync0),
            (std::vector<std::uint8_t>{0xFA, 0xFB, 0x03, 0x00, 0x00, 0x00}));
  // ENABLE 1: FA FB 06 04 3B 01 00 + checksum 0x043B ^ ... = words 043B, 0100.
  EXPECT_EQ(p2os::CommandPacket(p2os::kEnable, 1),
            (std::vector<std::uint8_t>{0xFA, 0xFB, 0x06, 0x04, 0x3B, 0x01, 0x00, 0x05, 0x3B}));
}

TEST(P2osProtocol, OddLengthPayloadXorsTheLastByte) {
  const std::uint8_t payload[] = {0x01, 0x02, 0x03};
  EXPECT_EQ(p2os::Checksum(payload, 3), 0x0102 ^ 0x03);
}

TEST(P2osProtocol, NegativeArgumentsUseTheirTypeByte) {
  const auto packet = p2os::CommandPacket(p2os::kVel, -250);
  Result<int> arg = p2os::CommandArgument({packet.begin() + 3, packet.end() - 2});
  ASSERT_TRUE(arg);
  EXPECT_EQ(*arg, -250);
  EXPECT_EQ(packet[4], p2os::kArgNegInt);
}

TEST(P2osProtocol, SipRoundTripsAndSkipsCorruption) {
  p2os::Sip sip;
  sip.moving = true;
  sip.x_raw = 0x7FF0;
  sip.y_raw = 12;
  sip.theta_raw = -1024;
  sip.left_mmps = -100;
  sip.right_mmps = 300;
  sip.battery_dv = 128;
  sip.stall_right = true;
  sip.rotvel_ddps = 450;
  auto bad = p2os::Encode(p2os::EncodeSip(sip));
  bad[8] ^= 0x40;
  auto bytes = bad;
  const auto good = p2os::Encode(p2os::EncodeSip(sip));
  bytes.insert(bytes.end(), good.begin(), good.end());
  p2os::PacketReader reader;
  reader.Feed(bytes.data(), bytes.size());
  auto payload = reader.Next();
  ASSERT_TRUE(payload);
  Result<p2os::Sip> back = p2os::DecodeSip(*payload);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->x_raw, 0x7FF0);
  EXPECT_EQ(back->theta_raw, -1024);
  EXPECT_EQ(back->left_mmps, -100);
  EXPECT_TRUE(back->stall_right);
  EXPECT_FALSE(back->stall_left);
  EXPECT_EQ(back->rotvel_ddps, 450);
  EXPECT_EQ(reader.checksum_errors(), 1u);
}

class P2osDriverTest : public ::testing::Test {
 protected:
  P2osDriverConfig Config() const {
    P2osDriverConfig c;
    c.device = emulator_.path();
    c.baud = 38400;
    return c;
  }
  P2osEmulator emulator_{P2osEmulatorConfig{38400}};
};

TEST_F(P2osDriverTest, HandshakeOpensAndEnablesTheMotors) {
  P2osDriver driver(Config());
  EXPECT_EQ(driver.robot(), "pitchlab Pioneer p3at-sh");
  EXPECT_TRUE(emulator_.connected());
  // ENABLE has no reply in P2OS: the emulator's thread applies it when it reads it, which on a
  // loaded machine can be after the constructor returns (seen once under a parallel build).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (!emulator_.motors_enabled() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_TRUE(emulator_.motors_enabled());
}

TEST_F(P2osDriverTest, DrivingForwardAndTurningShowsInOdometry) {
  P2osDriver driver(Config());
  Result<sensors::Odometry> odom = driver.Drive(0.4, 0.0, 1.0);
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->x_m, 0.4, 0.08);  // SIPs every 100 ms: the last one is up to 0.1 s old
  EXPECT_NEAR(odom->y_m, 0.0, 0.01);
  EXPECT_NEAR(odom->v_mps, 0.4, 0.01);
  odom = driver.Drive(0.0, 0.5, 1.0);
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->yaw_rad, 0.5, 0.1);
  EXPECT_NEAR(odom->omega_rps, 0.5, 0.01);
  odom = driver.Drive(0.0, 0.0, 0.3);
  ASSERT_TRUE(odom);
  EXPECT_NEAR(odom->v_mps, 0.0, 1e-3);
}

TEST_F(P2osDriverTest, CorruptedSipsAreSkipped) {
  P2osDriver driver(Config());
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kFlip;
  plan.probability = 0.2;
  plan.seed = 3;
  emulator_.SetFaults(plan);
  Result<sensors::Odometry> odom = driver.Drive(0.3, 0.0, 1.0);
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->x_m, 0.3, 0.1);
  EXPECT_GT(driver.checksum_errors(), 0u);
}

TEST_F(P2osDriverTest, SilentRobotIsATimeout) {
  P2osDriver driver(Config());
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kSilent;
  emulator_.SetFaults(plan);
  Result<sensors::Odometry> odom = driver.Drive(0.1, 0.0, 1.0);
  ASSERT_FALSE(odom);
  EXPECT_EQ(odom.error().code, Error::Code::kTimeout);
}

TEST_F(P2osDriverTest, UnpluggedRobotIsADeviceError) {
  P2osDriver driver(Config());
  emulator_.Unplug();
  Result<sensors::Odometry> odom = driver.Drive(0.1, 0.0, 0.5);
  ASSERT_FALSE(odom);
  EXPECT_EQ(odom.error().code, Error::Code::kDevice);
}

// Each fault on the robot's SIPs: odometry stays right (a mangled SIP is never integrated).
class P2osFaultTest : public P2osDriverTest,
                      public ::testing::WithParamInterface<FaultPlan::Kind> {};

TEST_P(P2osFaultTest, OdometryStaysRightThroughTheFault) {
  P2osDriver driver(Config());
  FaultPlan plan;
  plan.kind = GetParam();
  plan.probability = 0.3;
  plan.delay_ms = 150;  // well inside sip_timeout_ms
  plan.seed = 5;
  emulator_.SetFaults(plan);
  Result<sensors::Odometry> odom = driver.Drive(0.3, 0.0, 1.0);
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->x_m, 0.3, 0.1);
  EXPECT_NEAR(odom->y_m, 0.0, 0.01);
  EXPECT_NEAR(odom->v_mps, 0.3, 0.01);
  EXPECT_GT(emulator_.stats().faults, 0u);
  if (GetParam() != FaultPlan::Kind::kDelay) EXPECT_GT(driver.checksum_errors(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Faults, P2osFaultTest,
                         ::testing::Values(FaultPlan::Kind::kDrop, FaultPlan::Kind::kDuplicate,
                                           FaultPlan::Kind::kDelay),
                         [](const auto& info) {
                           switch (info.param) {
                             case FaultPlan::Kind::kDrop:
                               return std::string("drop");
                             case FaultPlan::Kind::kDuplicate:
                               return std::string("duplicate");
                             default:
                               return std::string("delay");
                           }
                         });

TEST_F(P2osDriverTest, UnplugWhileDrivingIsADeviceErrorNamingTheDevice) {
  P2osDriver driver(Config());
  std::thread unplug([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // SIPs are flowing by now
    emulator_.Unplug();
  });
  Result<sensors::Odometry> odom = driver.Drive(0.2, 0.0, 3.0);
  unplug.join();
  ASSERT_FALSE(odom);
  EXPECT_EQ(odom.error().code, Error::Code::kDevice);
  EXPECT_NE(odom.error().message.find(emulator_.path()), std::string::npos) << odom.error().message;
}

TEST_F(P2osDriverTest, ClosingTheDriverStopsTheRobotAndDisablesTheMotors) {
  {
    P2osDriver driver(Config());
    ASSERT_TRUE(driver.Drive(0.3, 0.2, 0.3));
    ASSERT_TRUE(emulator_.motors_enabled());
    ASSERT_GT(emulator_.command().first, 0.0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (emulator_.connected() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_FALSE(emulator_.connected());
  EXPECT_FALSE(emulator_.motors_enabled());
  EXPECT_EQ(emulator_.command(), std::make_pair(0.0, 0.0));
}

TEST(P2osDriverStartup, NoRobotThrowsNamingTheDeviceAndStep) {
  P2osEmulator emulator{P2osEmulatorConfig{38400}};
  FaultPlan plan;
  plan.kind = FaultPlan::Kind::kSilent;
  emulator.SetFaults(plan);
  P2osDriverConfig config;
  config.device = emulator.path();
  config.baud = 38400;
  config.sync_attempts = 1;
  try {
    P2osDriver driver(config);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(emulator.path()), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("SYNC0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pitchlab::hw
