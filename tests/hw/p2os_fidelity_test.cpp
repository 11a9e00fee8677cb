// The P2OS emulator and the P3 driver against the exact bytes Pioneer clients and robots send
// (issue 17, items 6-11): VEL2 wheel speeds, the laser's auxiliary power, the robot subclass's
// conversion factors, the keep-alive during a scan, and a parked base's odometry. Requests are
// literal packets (checksums included); replies are checked byte by byte.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include "client_wire.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/hw/p2os_driver.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"

namespace pitchlab::hw {
namespace {

using namespace client;  // NOLINT: the shared client-side helpers

const Bytes kSync0 = {0xFA, 0xFB, 0x03, 0x00, 0x00, 0x00};
const Bytes kSync1 = {0xFA, 0xFB, 0x03, 0x01, 0x00, 0x01};  // also OPEN once synced
const Bytes kSync2 = {0xFA, 0xFB, 0x03, 0x02, 0x00, 0x02};
const Bytes kEnable1 = {0xFA, 0xFB, 0x06, 0x04, 0x3B, 0x01, 0x00, 0x05, 0x3B};

// The next packet's payload (framing and checksum by pitchlab's reader; the payload bytes are
// what the tests check).
std::optional<Bytes> NextPayload(Wire& wire, p2os::PacketReader& reader,
                                 milliseconds timeout = kReplyTimeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (auto payload = reader.Next()) return *payload;
    const auto b = wire.Byte(deadline);
    if (!b) return std::nullopt;
    reader.Feed(&*b, 1);
  }
}

std::optional<Bytes> NextSip(Wire& wire, p2os::PacketReader& reader) {
  while (auto p = NextPayload(wire, reader)) {
    if ((*p)[0] == 0x32 || (*p)[0] == 0x33) return p;
  }
  return std::nullopt;
}

// SYNC0/1/2, OPEN and ENABLE 1 as ROS p2os sends them.
void Connect(Wire& wire, p2os::PacketReader& reader) {
  for (const Bytes* step : {&kSync0, &kSync1, &kSync2}) {
    wire.Write(*step);
    ASSERT_TRUE(NextPayload(wire, reader)) << "no echo";
  }
  wire.Write(kSync1);  // OPEN
  wire.Write(kEnable1);
}

int Le16s(const Bytes& p, std::size_t at) { return std::int16_t(p[at] | (p[at + 1] << 8)); }

// A skid-steer base like the simulated P3-AT: it turns (v, omega) into wheel speeds with its
// effective track (~0.96 m, the simulator's track x track_factor), not the 0.33 m axle.
struct SkidSteer {
  static constexpr double kTrack_m = 0.96;
  std::mutex mutex;
  double v = 0.0, w = 0.0;
  BasePhysics Physics() {
    BasePhysics p;
    p.command = [this](double v_mps, double w_rps) {
      std::lock_guard<std::mutex> lock(mutex);
      v = v_mps, w = w_rps;
    };
    p.state = [this] {
      std::lock_guard<std::mutex> lock(mutex);
      BaseState s;
      s.left_mps = v - 0.5 * kTrack_m * w;
      s.right_mps = v + 0.5 * kTrack_m * w;
      s.omega_rps = w;
      return s;
    };
    p.track_m = kTrack_m;
    return p;
  }
};

TEST(P2osVel2, TheWheelsReportTheCommandedSpeedsOnASkidSteerBase) {
  SkidSteer base;
  P2osEmulator emulator{P2osEmulatorConfig{}, base.Physics()};
  Wire wire(emulator.path(), 9600);
  p2os::PacketReader reader;
  Connect(wire, reader);
  // VEL2 left 10 x 20 = 200 mm/s, right 15 x 20 = 300 mm/s (ROS p2os: right in byte 2).
  wire.Write({0xFA, 0xFB, 0x06, 0x20, 0x3B, 0x0F, 0x0A, 0x2F, 0x45});
  std::this_thread::sleep_for(milliseconds(250));
  wire.Flush();
  reader.Clear();
  const auto sip = NextSip(wire, reader);
  ASSERT_TRUE(sip);
  EXPECT_EQ((*sip)[0], 0x33);
  EXPECT_EQ(Le16s(*sip, 7), 200);  // LVEL [mm/s]
  EXPECT_EQ(Le16s(*sip, 9), 300);  // RVEL
  // ROTVEL (0.1 deg/s): 100 mm/s difference over the 0.96 m track = 5.97 deg/s.
  EXPECT_EQ(Le16s(*sip, 28), 60);
}

TEST(P2osAuxPower, SwitchingOutput11OffAndOnRestartsTheLaserAt9600) {
  Lms200Emulator lms{Lms200EmulatorConfig{}};
  BasePhysics physics;
  physics.aux_power = [&lms](int output, bool on) {  // as `hw emulate` wires them
    if (output == p2os::kLaserPowerOutput) lms.SetPowered(on);
  };
  P2osEmulator base{P2osEmulatorConfig{}, physics};
  Wire robot(base.path(), 9600);
  p2os::PacketReader reader;
  Connect(robot, reader);
  Wire laser(lms.path(), 9600);
  ASSERT_TRUE(SicktoolboxTransact(laser, {0x20, 0x40}));  // the laser left at 38400
  laser.SetBaud(38400);
  // ARIA: com2Bytes(31, 11, 0); sleep 1 s; com2Bytes(31, 11, 1).
  robot.Write({0xFA, 0xFB, 0x06, 0x1F, 0x3B, 0x00, 0x0B, 0x1F, 0x46});
  ASSERT_TRUE(Eventually([&] { return !lms.powered(); }));
  EXPECT_FALSE(SicktoolboxTransact(laser, {0x31}, kWrongRateWait)) << "an unpowered laser answered";
  laser.SetBaud(9600);
  robot.Write({0xFA, 0xFB, 0x06, 0x1F, 0x3B, 0x01, 0x0B, 0x20, 0x46});
  // Powered again: 9600 baud and the power-on telegram.
  const auto deadline = Clock::now() + kReplyTimeout;
  std::optional<Bytes> power_on;
  while ((power_on = SicktoolboxMessage(laser, deadline)) && (*power_on)[0] != 0x90) {
  }
  ASSERT_TRUE(power_on) << "no power-on telegram after the power cycle";
  EXPECT_EQ(std::string(power_on->begin() + 1, power_on->begin() + 13), "LMS200;30106");
  EXPECT_TRUE(SicktoolboxTransact(laser, {0x31}));
}

// A robot that is not ours: a P3-AT with uARCS firmware ("p3at", DistConvFactor 0.465) that
// has driven 0.43 m, speaking literal bytes.
class UarcsP3at final : public EmulatedDevice {
 public:
  explicit UarcsP3at(std::string subclass) : EmulatedDevice("uarcs", 9600), subclass_(subclass) {
    Start();
  }
  ~UarcsP3at() override { Stop(); }

 private:
  void OnBytes(const std::uint8_t* bytes, std::size_t size) override {
    reader_.Feed(bytes, size);
    while (auto p = reader_.Next()) {
      if (p->size() != 1) continue;
      if ((*p)[0] == 0 && !open_) Send(kSync0);
      if ((*p)[0] == 1 && !open_ && synced_) open_ = true;
      if ((*p)[0] == 1 && !open_ && !synced_) Send(kSync1);
      if ((*p)[0] == 2 && !open_) {
        // "fake", "Pioneer", subclass.
        Send(subclass_ == "p3at"
                 ? Bytes{0xFA, 0xFB, 0x15, 0x02, 0x66, 0x61, 0x6B, 0x65, 0x00, 0x50, 0x69, 0x6F,
                         0x6E, 0x65, 0x65, 0x72, 0x00, 0x70, 0x33, 0x61, 0x74, 0x00, 0x31, 0xB4}
                 : Bytes{0xFA, 0xFB, 0x15, 0x02, 0x66, 0x61, 0x6B, 0x65, 0x00, 0x50, 0x69, 0x6F,
                         0x6E, 0x65, 0x65, 0x72, 0x00, 0x70, 0x39, 0x7A, 0x7A, 0x00, 0x4A, 0xC0});
        synced_ = true;
      }
    }
  }
  void OnIdle() override {
    if (!open_ || Clock::now() < next_) return;
    next_ = Clock::now() + milliseconds(100);
    // Stopped, XPOS 925 units (= 430 mm at 0.465 mm a unit), battery 12.8 V, motors on.
    Send({0xFA, 0xFB, 0x1B, 0x32, 0x9D, 0x03, 0x00, 0x00, 0x00, 0x00,
          0x00, 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x00, 0x00, 0x01,
          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x37, 0x1D});
  }
  std::string subclass_;
  p2os::PacketReader reader_;
  bool synced_ = false, open_ = false;
  Clock::time_point next_{};
};

TEST(P2osSubclass, ThePositionIsScaledByTheSubclassesDistanceFactor) {
  UarcsP3at robot("p3at");
  P2osDriverConfig config;
  config.device = robot.path();
  P2osDriver driver(config);
  EXPECT_EQ(driver.robot(), "fake Pioneer p3at");
  EXPECT_DOUBLE_EQ(driver.params().dist_conv_mm, 0.465);
  Result<sensors::Odometry> odom = driver.ReadOdometry();
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->x_m, 0.430, 0.0005);  // 925 x 0.465 mm, not 0.925 m
}

TEST(P2osSubclass, AnUnknownSubclassIsRefusedNamingIt) {
  UarcsP3at robot("p9zz");
  P2osDriverConfig config;
  config.device = robot.path();
  try {
    P2osDriver driver(config);
    FAIL() << "connected to a robot whose units are unknown";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'p9zz'"), std::string::npos) << what;
    EXPECT_NE(what.find(robot.path()), std::string::npos) << what;
    EXPECT_NE(what.find("p3at-sh"), std::string::npos) << what;  // the known ones listed
  }
}

TEST(P2osSubclass, TheEmulatorSpeaksTheUnitsOfTheSubclassItClaims) {
  P2osEmulatorConfig p3at;
  p3at.subtype = "p3at";
  P2osEmulator emulator{p3at};
  P2osDriverConfig config;
  config.device = emulator.path();
  P2osDriver driver(config);
  Result<sensors::Odometry> odom = driver.Drive(0.3, 0.0, 1.0);
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->x_m, 0.3, 0.08);  // SIPs every 100 ms: the last one is up to 0.1 s old
  EXPECT_NEAR(odom->v_mps, 0.3, 0.01);
  P2osEmulatorConfig unknown;
  unknown.subtype = "p9zz";
  EXPECT_THROW(P2osEmulator{unknown}, std::invalid_argument);
}

TEST(P2osKeepAlive, ADriverLeftAloneDuringAScanKeepsTheRobotAwakeAndItsSipsRead) {
  P2osEmulator emulator{P2osEmulatorConfig{}};  // 9600, the P3's power-on rate
  P2osDriverConfig config;
  config.device = emulator.path();
  P2osDriver driver(config);
  ASSERT_TRUE(driver.Drive(0.2, 0.0, 0.1));
  // The mission scans for ~45 s without touching the base; 3 s is past the 2 s watchdog.
  double longest_quiet_s = 0.0;
  const auto until = Clock::now() + std::chrono::seconds(3);
  while (Clock::now() < until) {
    longest_quiet_s = std::max(longest_quiet_s, emulator.seconds_since_client_packet());
    std::this_thread::sleep_for(milliseconds(20));
  }
  EXPECT_LT(longest_quiet_s, 1.0);                   // a PULSE at least every second
  EXPECT_NEAR(emulator.command().first, 0.2, 1e-9);  // the watchdog never fired
  // Read as they come: at most one SIP (37 bytes) in flight, not 30 piled up.
  EXPECT_LT(emulator.unread_bytes(), 2 * 37u);
  Result<sensors::Odometry> odom = driver.ReadOdometry();
  ASSERT_TRUE(odom) << odom.error().message;
  EXPECT_NEAR(odom->x_m, 0.2 * 3.1, 0.1);
}

// "The robot will automatically resume activity, including motion, as soon as communications
// are restored" (Pioneer 3 Operations Manual, Safety Watchdogs): a client quiet past the 2 s
// watchdog stops the motors, and its next packet, a PULSE, sets them going at its last command
// again (ROS p2os sends a velocity only when it changes; a robot that stayed stopped would not
// move again).
TEST(P2osWatchdog, MotorsStopWhenTheClientGoesQuietAndResumeWhenItSpeaksAgain) {
  SkidSteer base;
  P2osEmulator emulator{P2osEmulatorConfig{}, base.Physics()};
  Wire wire(emulator.path(), 9600);
  p2os::PacketReader reader;
  Connect(wire, reader);
  const auto v = [&base] {
    std::lock_guard<std::mutex> lock(base.mutex);
    return base.v;
  };
  wire.Write({0xFA, 0xFB, 0x06, 0x0B, 0x3B, 0xC8, 0x00, 0xD3, 0x3B});  // VEL 200 mm/s
  ASSERT_TRUE(Eventually([&] { return std::abs(v() - 0.2) < 1e-9; }));
  ASSERT_TRUE(Eventually([&] { return v() == 0.0; }, milliseconds(3000))) << "no watchdog stop";
  EXPECT_EQ(emulator.command().first, 0.0);
  wire.Write({0xFA, 0xFB, 0x03, 0x00, 0x00, 0x00});  // PULSE
  EXPECT_TRUE(Eventually([&] { return std::abs(v() - 0.2) < 1e-9; })) << "did not resume";
  EXPECT_NEAR(emulator.command().first, 0.2, 1e-9);
}

// STOP (29) ramps down like any command of zero; E_STOP (55) "overrides decel" (ARIA's
// ArCommands): the physics is told to stop at once.
TEST(P2osEStop, AnEmergencyStopSkipsTheDecelerationAPlainStopKeeps) {
  SkidSteer base;
  BasePhysics physics = base.Physics();
  std::atomic<int> emergency_stops{0};
  physics.emergency_stop = [&] { ++emergency_stops; };
  P2osEmulator emulator{P2osEmulatorConfig{}, physics};
  Wire wire(emulator.path(), 9600);
  p2os::PacketReader reader;
  Connect(wire, reader);
  const Bytes vel200 = {0xFA, 0xFB, 0x06, 0x0B, 0x3B, 0xC8, 0x00, 0xD3, 0x3B};
  wire.Write(vel200);
  ASSERT_TRUE(Eventually([&] { return std::abs(emulator.command().first - 0.2) < 1e-9; }));
  wire.Write({0xFA, 0xFB, 0x03, 0x1D, 0x00, 0x1D});  // STOP
  ASSERT_TRUE(Eventually([&] { return emulator.command().first == 0.0; }));
  EXPECT_EQ(emergency_stops, 0);
  wire.Write(vel200);
  ASSERT_TRUE(Eventually([&] { return std::abs(emulator.command().first - 0.2) < 1e-9; }));
  wire.Write({0xFA, 0xFB, 0x03, 0x37, 0x00, 0x37});  // E_STOP
  EXPECT_TRUE(Eventually([&] { return emergency_stops == 1; }));
  EXPECT_EQ(emulator.command().first, 0.0);
}

TEST(P2osSetO, SetoPutsTheReportedPoseBackToTheOrigin) {
  P2osEmulator emulator{P2osEmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  p2os::PacketReader reader;
  Connect(wire, reader);
  wire.Write({0xFA, 0xFB, 0x06, 0x0B, 0x3B, 0xC8, 0x00, 0xD3, 0x3B});  // VEL 200
  std::this_thread::sleep_for(milliseconds(500));
  wire.Write({0xFA, 0xFB, 0x03, 0x1D, 0x00, 0x1D});  // STOP
  std::this_thread::sleep_for(milliseconds(200));
  wire.Flush();
  reader.Clear();
  const auto moved = NextSip(wire, reader);
  ASSERT_TRUE(moved);
  EXPECT_GT(Le16s(*moved, 1), 50);                   // ~100 mm driven
  wire.Write({0xFA, 0xFB, 0x03, 0x07, 0x00, 0x07});  // SETO
  std::this_thread::sleep_for(milliseconds(200));
  wire.Flush();
  reader.Clear();
  const auto reset = NextSip(wire, reader);
  ASSERT_TRUE(reset);
  EXPECT_EQ(Bytes(reset->begin() + 1, reset->begin() + 7), Bytes(6, 0x00));  // x, y, th
}

// A parked base whose simulation creeps: the heading drifts (a gyro's bias), the wheel speeds
// flicker +-1 mm/s (a position loop), the wheels stay within a fraction of an encoder tick.
struct CreepingBase {
  static constexpr double kTick_m = 2.0 * 3.14159265358979 * 0.11 / 500;  // 500-tick encoder
  std::mutex mutex;
  int calls = 0;
  double v = 0.0, pushed_m = 0.0;
  Clock::time_point t0 = Clock::now();
  BasePhysics Physics() {
    BasePhysics p;
    p.command = [this](double v_mps, double) {
      std::lock_guard<std::mutex> lock(mutex);
      v = v_mps;
    };
    p.state = [this] {
      std::lock_guard<std::mutex> lock(mutex);
      const double t = std::chrono::duration<double>(Clock::now() - t0).count();
      BaseState s;
      s.yaw_rad = 0.02 * t;  // 69 deg/min: drift a test can see in a second
      s.x_m = 0.001 * t + pushed_m;
      const double flicker = (++calls % 2 ? 0.001 : -0.001) + v;
      s.left_mps = s.right_mps = flicker;
      s.left_travel_m = s.right_travel_m = 0.2 * kTick_m * std::sin(t) + pushed_m;
      return s;
    };
    p.encoder_tick_m = kTick_m;
    return p;
  }
};

TEST(P2osStandstill, AParkedBaseReportsZeroSpeedAndAConstantPose) {
  CreepingBase base;
  P2osEmulator emulator{P2osEmulatorConfig{}, base.Physics()};
  Wire wire(emulator.path(), 9600);
  p2os::PacketReader reader;
  Connect(wire, reader);
  const auto first = NextSip(wire, reader);
  ASSERT_TRUE(first);
  for (int i = 0; i < 12; ++i) {
    const auto sip = NextSip(wire, reader);
    ASSERT_TRUE(sip);
    EXPECT_EQ((*sip)[0], 0x32) << "SIP " << i << ": moving";
    EXPECT_EQ(Bytes(sip->begin() + 1, sip->begin() + 11),
              Bytes(first->begin() + 1, first->begin() + 11))
        << "SIP " << i << ": pose or wheel speeds changed";
    EXPECT_EQ(Le16s(*sip, 28), 0) << "SIP " << i << ": ROTVEL";
  }
  {
    std::lock_guard<std::mutex> lock(base.mutex);
    base.pushed_m = 10 * CreepingBase::kTick_m;  // pushed 14 mm: the encoders count it
  }
  std::this_thread::sleep_for(milliseconds(250));
  wire.Flush();
  reader.Clear();
  const auto pushed = NextSip(wire, reader);
  ASSERT_TRUE(pushed);
  EXPECT_NEAR(Le16s(*pushed, 1) - Le16s(*first, 1), 1000.0 * 10 * CreepingBase::kTick_m, 1.5);
  // Driving: the physics' speeds are reported as they are.
  wire.Write({0xFA, 0xFB, 0x06, 0x0B, 0x3B, 0xC8, 0x00, 0xD3, 0x3B});  // VEL 200
  std::this_thread::sleep_for(milliseconds(250));
  wire.Flush();
  reader.Clear();
  const auto moving = NextSip(wire, reader);
  ASSERT_TRUE(moving);
  EXPECT_EQ((*moving)[0], 0x33);
  EXPECT_NEAR(Le16s(*moving, 7), 200, 1);
}

}  // namespace
}  // namespace pitchlab::hw
