// Independently written clients against the emulators: each test replays, byte for byte, the
// request sequence one published driver sends and parses the replies the way that driver does
// (its offsets, masks and acceptance checks), not with pitchlab's decoders. What each client does
// and where it is written down: docs/hardware_interop.md. The clients' own timeouts are shortened
// where they only wait for a device that ignores a request at the wrong rate.

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/hw/lms200_protocol.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"
#include "pitchlab/hw/p2os_protocol.hpp"
#include "pitchlab/hw/serial_port.hpp"

#include "client_wire.hpp"

namespace pitchlab::hw {
namespace {

using namespace client;  // NOLINT: the shared client-side helpers

// SickLMS2xx::_getSickStatus's reading of the 0xB1 payload (command at index 0).
struct SicktoolboxStatus {
  std::string version;
  int operating_mode, device_status, measuring_mode, scan_angle, scan_resolution, units;
};
SicktoolboxStatus ParseSicktoolboxStatus(const Bytes& p) {
  // Its buffer is zero-filled, so a short reply reads as zeros: require the full block.
  EXPECT_EQ(p.size(), 1 + lms200::kStatusBlockBytes + 1);
  Bytes b = p;
  b.resize(std::max<std::size_t>(b.size(), 160), 0);
  return {std::string(b.begin() + 1, b.begin() + 8),
          b[8],
          b[9],
          b[102],
          Le16(b, 107),
          Le16(b, 109),
          b[122]};
}

TEST(SicktoolboxClient, InitialiseSetVariantAndUnitsStreamAndUninitialise) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  // Initialize(SICK_BAUD_38400): the port at the default 9600, then _setSessionBaud.
  Wire wire(emulator.path(), 9600);
  auto reply = SicktoolboxTransact(wire, {0x20, 0x40});
  ASSERT_TRUE(reply) << "no 0xA0 to the baud switch at 9600";
  wire.SetBaud(38400);
  // _setSickOpModeMonitorRequestValues: payload[1] must be 0 (switchSickOperatingMode).
  reply = SicktoolboxTransact(wire, {0x20, 0x25});
  ASSERT_TRUE(reply);
  EXPECT_EQ((*reply)[1], 0x00);
  // _getSickType: the string between the command and the status byte.
  reply = SicktoolboxTransact(wire, {0x3A});
  ASSERT_TRUE(reply);
  const std::string type(reply->begin() + 1, reply->end() - 1);
  EXPECT_NE(type.find("LMS200;30106"), std::string::npos) << type;  // SICK_LMS_TYPE_200_30106
  // _getSickStatus.
  reply = SicktoolboxTransact(wire, {0x31});
  ASSERT_TRUE(reply);
  SicktoolboxStatus status = ParseSicktoolboxStatus(*reply);
  EXPECT_EQ(status.version, "V02.10 ");
  EXPECT_EQ(status.operating_mode, 0x25);
  EXPECT_EQ(status.device_status, 0);
  EXPECT_EQ(status.scan_angle, 180);
  EXPECT_EQ(status.scan_resolution, 50);
  EXPECT_EQ(status.units, 0);  // SICK_MEASURING_UNITS_CM
  // _getSickConfig: _parseSickConfigProfile(&payload[1]) reads blocks A..A4 (34 bytes).
  reply = SicktoolboxTransact(wire, {0x74});
  ASSERT_TRUE(reply);
  ASSERT_EQ(reply->size(), 1 + 34 + 1u);
  Bytes config(reply->begin() + 1, reply->begin() + 35);
  EXPECT_EQ(config[5], 0x00);  // measuring mode: 8 m / 80 m, fields A B and dazzle
  EXPECT_EQ(config[6], 0x00);  // units: cm

  // SetSickVariant(100 deg, 0.25 deg): request mode first, then 3B 64 00 19 00;
  // payload[1] == 1 accepted, angle and resolution echoed at payload[2..5].
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x25}));
  reply = SicktoolboxTransact(wire, {0x3B, 0x64, 0x00, 0x19, 0x00});
  ASSERT_TRUE(reply);
  EXPECT_EQ((*reply)[1], 0x01);
  EXPECT_EQ(Le16(*reply, 2), 100);
  EXPECT_EQ(Le16(*reply, 4), 25);

  // SetSickMeasuringUnits(MM) -> _setSickConfig: installation mode with the password, then
  // 0x77 + the 34-byte block (units at block E); payload[1] must be 1 and the new block follows.
  Bytes password = {0x20, 0x00};
  const Bytes sick_lms = Text("SICK_LMS");
  password.insert(password.end(), sick_lms.begin(), sick_lms.end());
  reply = SicktoolboxTransact(wire, password);
  ASSERT_TRUE(reply);
  EXPECT_EQ((*reply)[1], 0x00);
  config[6] = 0x01;
  Bytes write = {0x77};
  write.insert(write.end(), config.begin(), config.end());
  reply = SicktoolboxTransact(wire, write, milliseconds(3000));  // CONFIG_MESSAGE_TIMEOUT
  ASSERT_TRUE(reply);
  EXPECT_EQ((*reply)[1], 0x01) << "configuration refused";
  EXPECT_EQ((*reply)[2 + 6], 0x01);
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x25}));
  reply = SicktoolboxTransact(wire, {0x31});
  ASSERT_TRUE(reply);
  status = ParseSicktoolboxStatus(*reply);
  EXPECT_EQ(status.units, 1);  // the wrapper scales by 0.001 from this byte
  EXPECT_EQ(status.scan_angle, 100);
  EXPECT_EQ(status.scan_resolution, 25);

  // GetSickScan: stream mode, then the next 0xB0 (_parseSickScanProfileB0, measuring mode 0:
  // 13 value bits).
  reply = SicktoolboxTransact(wire, {0x20, 0x24});
  ASSERT_TRUE(reply);
  EXPECT_EQ((*reply)[1], 0x00);
  EXPECT_TRUE(emulator.streaming());
  std::optional<Bytes> scan;
  const auto deadline = Clock::now() + kReplyTimeout;
  while ((scan = SicktoolboxMessage(wire, deadline)) && (*scan)[0] != 0xB0) {
  }
  ASSERT_TRUE(scan) << "no measured values streamed";
  const Bytes& s = *scan;
  const int count = s[1] + 256 * (s[2] & 0x03);
  EXPECT_EQ(count, 401);             // 100 deg at 0.25 deg
  EXPECT_EQ((s[2] & 0x18) >> 3, 0);  // partial scan index
  EXPECT_EQ(s.size(), 1 + 2 + 2 * 401 + 1u);
  const int centre = s[3 + 2 * 200] + 256 * (s[3 + 2 * 200 + 1] & 0x1F);
  EXPECT_EQ(centre, 3000);  // the emulator's flat wall 3 m ahead, in mm

  // Uninitialize: request mode, then back to 9600; the device answers there.
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x25}));
  EXPECT_FALSE(emulator.streaming());
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x42}));
  wire.SetBaud(9600);
  EXPECT_TRUE(SicktoolboxTransact(wire, {0x31}));
}

TEST(SicktoolboxClient, FindsADeviceLeftAtAnotherRateWithTheErrorRequest) {
  // A device still at 38400 from an earlier session: the first baud switch at 9600 times out,
  // then _testSickBaud asks for the error list (0x32) at 9600, 19200, 38400.
  Lms200EmulatorConfig at38400;
  at38400.power_on_baud = 38400;
  Lms200Emulator emulator{at38400};
  Wire wire(emulator.path(), 9600);
  EXPECT_FALSE(SicktoolboxTransact(wire, {0x20, 0x40}, kWrongRateWait));
  int found = 0;
  for (int baud : {9600, 19200, 38400}) {
    wire.SetBaud(baud);
    auto reply = SicktoolboxTransact(wire, {0x32}, kWrongRateWait);
    if (!reply) continue;
    found = baud;
    // _getSickErrors: (payload length - 2) / 2 error pairs.
    EXPECT_EQ((reply->size() - 2) / 2, 0u);
    break;
  }
  EXPECT_EQ(found, 38400);
}

// Player's sicklms200 (SickLMS200::ReadFromLaser): a five-byte window until STX, 0x80; with
// `ack` only a reply whose command is 0xA0 (its "ACK") or 0x92 (its "NACK") ends the search.
// Returns the command and data (LEN - 1 bytes, the status byte excluded); the CRC covers header,
// data and the status byte.
std::optional<Bytes> PlayerRead(Wire& wire, bool ack, milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  std::uint8_t header[5] = {0, 0, 0, 0, 0};
  for (;;) {
    const auto b = wire.Byte(deadline);
    if (!b) return std::nullopt;
    header[4] = *b;
    if (header[0] == 0x02 && header[1] == 0x80 &&
        (!ack || header[4] == 0xA0 || header[4] == 0x92)) {
      break;
    }
    std::memmove(header, header + 1, 4);
  }
  const int len = (header[2] | (header[3] << 8)) - 1;
  Bytes data = {header[4]};
  while (int(data.size()) < len) {
    const auto b = wire.Byte(deadline);
    if (!b) return std::nullopt;
    data.push_back(*b);
  }
  std::uint8_t footer[3];
  for (auto& f : footer) {
    const auto b = wire.Byte(deadline);
    if (!b) return std::nullopt;
    f = *b;
  }
  Bytes frame(header, header + 4);
  frame.insert(frame.end(), data.begin(), data.end());
  frame.push_back(footer[0]);
  if (lms200::Crc16(frame.data(), frame.size()) != (footer[1] | (footer[2] << 8))) {
    ADD_FAILURE() << "Player: CRC error, ignoring packet";
    return std::nullopt;
  }
  return data;
}

std::optional<Bytes> PlayerRequest(Wire& wire, const Bytes& request, bool ack,
                                   milliseconds timeout = kReplyTimeout) {
  wire.Flush();  // WriteToLaser: tcflush(TCIOFLUSH) before writing
  wire.Write(LmsRequest(request));
  return PlayerRead(wire, ack, timeout);
}

Bytes PlayerSetLaserMode() {
  Bytes request = {0x20, 0x00};
  const Bytes password = Text("SICK_LMS");
  request.insert(request.end(), password.begin(), password.end());
  return request;
}

TEST(PlayerSicklms200Client, SetupAtTheConfiguredRateFallsBackTo9600ConfiguresAndStreams) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  // Setup() with rate 38400, resolution 50, range_res 1 (mm), intensity on. OpenTerm at 9600,
  // then SetLaserMode at 38400 (twice, three tries each): a device at 9600 never answers.
  Wire wire(emulator.path(), 9600);
  wire.SetBaud(38400);
  for (int attempt = 0; attempt < 2; ++attempt) {
    EXPECT_FALSE(PlayerRequest(wire, PlayerSetLaserMode(), true, kWrongRateWait));
  }
  wire.SetBaud(9600);
  auto reply = PlayerRequest(wire, PlayerSetLaserMode(), true);
  ASSERT_TRUE(reply) << "no reply to SetLaserMode at 9600";
  ASSERT_EQ((*reply)[0], 0xA0);
  EXPECT_EQ((*reply)[1], 0x00);  // password accepted (Player does not look)
  // SetLaserSpeed(38400), then the terminal follows.
  reply = PlayerRequest(wire, {0x20, 0x40}, true, milliseconds(2000));
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xA0);
  wire.SetBaud(38400);
  // GetLaserType: strcpy from packet + 1 after NUL-terminating at len + 1.
  reply = PlayerRequest(wire, {0x3A}, false);
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xBA);
  EXPECT_EQ(std::string(reply->begin() + 1, reply->end()), "LMS200;30106");
  // SetLaserRes(180, 50): 0xBB, packet[1] != 0.
  reply = PlayerRequest(wire, {0x3B, 0xB4, 0x00, 0x32, 0x00}, false);
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xBB);
  EXPECT_NE((*reply)[1], 0x00);
  // SetLaserConfig(true): read the block, write it back with packet[6] (block D, measuring
  // mode) = 1 for intensity and packet[7] (block E, units) = 1 for mm, same length.
  reply = PlayerRequest(wire, {0x74}, false);
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xF4);
  Bytes packet = *reply;
  EXPECT_EQ(packet.size(), 1 + 34u);
  packet[0] = 0x77;
  packet[6] = 0x01;
  packet[7] = 0x01;
  reply = PlayerRequest(wire, packet, false);
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xF7);
  EXPECT_EQ((*reply)[1], 0x01);  // accepted (Player does not look)
  EXPECT_EQ(emulator.current().range_mode, sensors::Lms200RangeMode::kMm);
  // RequestLaserData(0, 360): 0x20 0x24, answered by the 0xA0 reply.
  reply = PlayerRequest(wire, {0x20, 0x24}, true);
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xA0);
  // ReadLaserData: count = raw[1] | (raw[2] & 0x3F) << 8; values from raw[3], range = & 0x1FFF.
  std::optional<Bytes> raw;
  const auto deadline = Clock::now() + kReplyTimeout;
  while ((raw = PlayerRead(wire, false, kReplyTimeout)) && (*raw)[0] != 0xB0 &&
         Clock::now() < deadline) {
  }
  ASSERT_TRUE(raw && (*raw)[0] == 0xB0) << "no scan streamed";
  const Bytes& r = *raw;
  const int count = r[1] | ((r[2] & 0x3F) << 8);
  ASSERT_EQ(count, 361);
  ASSERT_EQ(r.size(), 3 + 2 * 361u);
  const int centre = (r[3 + 2 * 180] | (r[4 + 2 * 180] << 8)) & 0x1FFF;
  EXPECT_EQ(centre, 3000);  // 3 m in mm: range_res 1
  const int edge = (r[3] | (r[4] << 8)) & 0x1FFF;
  EXPECT_GE(edge, lms200::kFirstSpecialCode);  // along the wall: a flag code, never a range
}

TEST(PlayerSicklms200Client, UnitsTheEmulatorCannotProduceAreRefusedInTheReply) {
  // Player's range_res 100 writes units 2 (dm); an LMS200 measures in cm or mm. The reply says
  // "not accepted" (0x00), which sicktoolbox checks; the device keeps its units.
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  ASSERT_TRUE(PlayerRequest(wire, PlayerSetLaserMode(), true));
  auto reply = PlayerRequest(wire, {0x74}, false);
  ASSERT_TRUE(reply);
  Bytes packet = *reply;
  packet[0] = 0x77;
  packet[7] = 0x02;
  reply = PlayerRequest(wire, packet, false);
  ASSERT_TRUE(reply);
  ASSERT_EQ((*reply)[0], 0xF7);
  EXPECT_EQ((*reply)[1], 0x00);
  EXPECT_EQ((*reply)[2 + 6], 0x00);  // the block in force: still cm
  EXPECT_EQ(emulator.current().range_mode, sensors::Lms200RangeMode::kCm);
}

// ---------------------------------------------------------------------------------------------
// Pioneer P2OS / ARCOS clients.

Bytes P2osPacket(const Bytes& payload) { return p2os::Encode(payload); }
Bytes P2osCommand(std::uint8_t command) { return P2osPacket({command}); }
// ARGINT / ARGNINT with the magnitude little-endian, as ROS p2os and ARIA's comInt build them.
Bytes P2osCommand(std::uint8_t command, int argument) {
  const int magnitude = argument < 0 ? -argument : argument;
  return P2osPacket({command, std::uint8_t(argument < 0 ? 0x1B : 0x3B),
                     std::uint8_t(magnitude & 0xFF), std::uint8_t((magnitude >> 8) & 0xFF)});
}

// One packet as ROS p2os (P2OSPacket::Receive) and ARIA (ArRobotPacketReceiver) read it: FA FB,
// the count, count bytes; the checksum (big-endian) over the payload as 16-bit words with an
// odd last byte XORed in. Returns the whole packet (header included: ROS indexes from it).
std::optional<Bytes> P2osReceive(Wire& wire, Clock::time_point deadline) {
  for (;;) {
    std::uint8_t prev = 0;
    for (;;) {
      const auto b = wire.Byte(deadline);
      if (!b) return std::nullopt;
      if (prev == 0xFA && *b == 0xFB) break;
      prev = *b;
    }
    const auto count = wire.Byte(deadline);
    if (!count) return std::nullopt;
    Bytes packet = {0xFA, 0xFB, *count};
    for (int i = 0; i < *count; ++i) {
      const auto b = wire.Byte(deadline);
      if (!b) return std::nullopt;
      packet.push_back(*b);
    }
    const std::size_t n = packet.size() - 2;  // end of the payload
    int sum = 0;
    std::size_t i = 3;
    for (; i + 1 < n; i += 2) sum = (sum + ((packet[i] << 8) | packet[i + 1])) & 0xFFFF;
    if (i < n) sum ^= packet[i];
    if (sum == ((packet[n] << 8) | packet[n + 1])) return packet;
  }
}

std::optional<Bytes> P2osReceive(Wire& wire, milliseconds timeout = kReplyTimeout) {
  return P2osReceive(wire, Clock::now() + timeout);
}

// ROS p2os SIP::ParseStandard on &packet[3]: fixed fields, then the sonars, then five bytes.
struct RosSip {
  int type, raw_x, raw_y, angle_units, lvel, rvel, battery, motors_enabled, sonars;
  bool lwstall, rwstall;
};
RosSip ParseRosSip(const Bytes& packet) {
  const std::uint8_t* b = packet.data() + 3;
  RosSip s{};
  s.type = b[0];
  s.raw_x = ((b[1] | (b[2] << 8)) & 0xEFFF) % 4096;
  s.raw_y = ((b[3] | (b[4] << 8)) & 0xEFFF) % 4096;
  s.angle_units = std::int16_t(b[5] | (b[6] << 8));
  s.lvel = std::int16_t(b[7] | (b[8] << 8));  // x VelConvFactor (1 for p3at-sh)
  s.rvel = std::int16_t(b[9] | (b[10] << 8));
  s.battery = b[11];
  s.lwstall = b[12] & 0x01;
  s.rwstall = b[13] & 0x01;
  s.motors_enabled = b[16];
  s.sonars = b[19];
  // timer (2), analog, digin, digout follow the sonars: the packet must hold them.
  EXPECT_GE(packet.size(), 3 + 20 + 3 * std::size_t(s.sonars) + 5 + 2u);
  return s;
}

// A SIP as ROS p2os accepts it in SendReceive: packet[3] in 0x30..0x34.
std::optional<Bytes> NextSip(Wire& wire, milliseconds timeout = kReplyTimeout) {
  const auto deadline = Clock::now() + timeout;
  while (auto packet = P2osReceive(wire, deadline)) {
    if ((*packet)[3] >= 0x30 && (*packet)[3] <= 0x34) return packet;
  }
  return std::nullopt;
}

// The name, class and subclass strings after the SYNC2 byte (ROS: snprintf from packet[4]).
std::vector<std::string> Sync2Strings(const Bytes& packet) {
  std::vector<std::string> out;
  std::size_t at = 4;
  for (int k = 0; k < 3 && at < packet.size() - 2; ++k) {
    std::string s;
    while (at < packet.size() - 2 && packet[at] != 0) s.push_back(char(packet[at++]));
    ++at;
    out.push_back(s);
  }
  return out;
}

// ROS p2os P2OSNode::Setup: SYNC0 (repeated while unanswered), SYNC1, SYNC2, each answered by
// a packet whose packet[3] is the same number; then the strings, OPEN, PULSE.
std::vector<std::string> RosP2osSync(Wire& wire) {
  std::optional<Bytes> reply;
  for (int tries = 0; tries < 4 && !(reply && (*reply)[3] == 0); ++tries) {
    wire.Write(P2osCommand(p2os::kSync0));
    reply = P2osReceive(wire, milliseconds(300));
    if (reply && (*reply)[3] != 0) {
      // "maybe P2OS is still running from last time": CLOSE, flush, start again.
      wire.Write(P2osCommand(p2os::kClose));
      std::this_thread::sleep_for(milliseconds(200));
      wire.Flush();
      reply.reset();
    }
  }
  EXPECT_TRUE(reply && (*reply)[3] == 0) << "no SYNC0 echo";
  wire.Write(P2osCommand(p2os::kSync1));
  reply = P2osReceive(wire);
  EXPECT_TRUE(reply && (*reply)[3] == 1) << "no SYNC1 echo";
  wire.Write(P2osCommand(p2os::kSync2));
  reply = P2osReceive(wire);
  EXPECT_TRUE(reply && (*reply)[3] == 2) << "no SYNC2 reply";
  if (!reply) return {};
  wire.Write(P2osCommand(p2os::kOpen));
  wire.Write(P2osCommand(p2os::kPulse));
  return Sync2Strings(*reply);
}

TEST(RosP2osClient, SetupFindsItsRobotParametersAndDrivesThroughSips) {
  P2osEmulator emulator{P2osEmulatorConfig{}};  // 9600: the first rate ROS p2os tries
  Wire wire(emulator.path(), 9600);
  const std::vector<std::string> names = RosP2osSync(wire);
  ASSERT_EQ(names.size(), 3u);
  EXPECT_EQ(names[0], "pitchlab");
  // PlayerRobotParams is looked up by class and subclass (strcasecmp); "Pioneer"/"p3at-sh" has
  // DistConvFactor and VelConvFactor 1: the SIP's mm and mm/s are taken as they are sent.
  EXPECT_EQ(names[1], "Pioneer");
  EXPECT_EQ(names[2], "p3at-sh");
  EXPECT_TRUE(Eventually([&] { return emulator.connected(); }));
  // ToggleSonarPower(0) through SendReceive: one packet back, and it must be a SIP.
  wire.Write(P2osCommand(p2os::kSonar, 0));
  auto sip = NextSip(wire);
  ASSERT_TRUE(sip) << "no SIP after OPEN";
  RosSip s = ParseRosSip(*sip);
  EXPECT_EQ(s.motors_enabled & 0x01, 0);
  EXPECT_EQ(s.battery, 128);  // 12.8 V: check_voltage reports OK above 11.75 V
  // ToggleMotorPower(1), then check_and_set_vel: VEL 200 mm/s, RVEL 10 deg/s.
  wire.Write(P2osCommand(p2os::kEnable, 1));
  wire.Write(P2osCommand(p2os::kVel, 200));
  wire.Write(P2osCommand(p2os::kRVel, 10));
  ASSERT_TRUE(Eventually([&] { return emulator.command().second > 0.0; }));
  wire.Flush();
  sip = NextSip(wire);
  ASSERT_TRUE(sip);
  s = ParseRosSip(*sip);
  EXPECT_EQ(s.motors_enabled & 0x01, 1);
  EXPECT_EQ(s.type, 0x33);  // moving
  EXPECT_NEAR(0.5 * (s.lvel + s.rvel), 200.0, 1.0);
  // FillStandard: angular.z = (rvel - lvel) * DiffConvFactor / 2 with the P3-AT's 0.0034.
  EXPECT_GT(s.rvel, s.lvel);
  EXPECT_NEAR(emulator.command().second, 10.0 * kPi / 180.0, 1e-9);
  // direct_wheel_vel_control: VEL2 with the right wheel in [2] and the left in [3], 20 mm/s
  // units (Vel2Divisor): 10 and 10 = 0.2 m/s straight.
  wire.Write(P2osPacket({p2os::kVel2, 0x3B, 10, 10}));
  ASSERT_TRUE(Eventually([&] { return std::abs(emulator.command().second) < 1e-9; }));
  EXPECT_NEAR(emulator.command().first, 0.2, 1e-9);
  // Shutdown: STOP, then CLOSE.
  wire.Write(P2osCommand(p2os::kStop));
  ASSERT_TRUE(Eventually([&] { return emulator.command().first == 0.0; }))
      << "STOP did not stop the robot";
  EXPECT_TRUE(emulator.motors_enabled());  // STOP keeps the motors enabled
  wire.Write(P2osCommand(p2os::kClose));
  EXPECT_TRUE(Eventually([&] { return !emulator.connected(); }));
}

TEST(RosP2osClient, ReconnectsToARobotLeftOpenByAnEarlierSession) {
  P2osEmulator emulator{P2osEmulatorConfig{}};
  {
    Wire first(emulator.path(), 9600);
    ASSERT_EQ(RosP2osSync(first).size(), 3u);
  }  // the earlier session ends without CLOSE: the robot still sends SIPs
  ASSERT_TRUE(Eventually([&] { return emulator.connected(); }));
  Wire wire(emulator.path(), 9600);
  std::this_thread::sleep_for(milliseconds(150));  // a SIP is on the way
  EXPECT_EQ(RosP2osSync(wire).size(), 3u);
  EXPECT_TRUE(Eventually([&] { return emulator.connected(); }));
}

// ARIA (ArRobot::asyncConnectHandler, ArRobotPacketSender): "WMS2\r" for a radio modem, then
// com(0), com(1), com(2) each waiting up to 1 s for the packet with that ID; comInt(OPEN, 1);
// the CONFIG packet is requested (comInt(CONFIG, 1)) and may never come: after 1 s ARIA uses its
// parameter file. Motion with comInt(VEL) / comInt(RVEL) and com2Bytes(VEL2, left, right),
// which passes (left << 8) + right through a short: above 0x7FFF it goes out as ARGNINT.
TEST(AriaClient, ConnectsOpensAndDrivesWithVelRvelAndVel2) {
  P2osEmulator emulator{P2osEmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  wire.Write(Text("WMS2\r"));
  for (std::uint8_t id : {0, 1, 2}) {
    wire.Write(P2osCommand(id));
    std::optional<Bytes> packet = P2osReceive(wire);
    ASSERT_TRUE(packet) << "no packet " << int(id);
    ASSERT_EQ((*packet)[3], id);
    if (id == 2) {
      const std::vector<std::string> names = Sync2Strings(*packet);
      ASSERT_EQ(names.size(), 3u);
      // madeConnection: the lowercased subtype selects ArRobotP3ATSH.
      EXPECT_EQ(names[2], "p3at-sh");
    }
  }
  wire.Write(P2osCommand(p2os::kOpen, 1));
  wire.Write(P2osCommand(p2os::kConfig, 1));
  // SIPs (ID 0x32 / 0x33) arrive; no CONFIG packet (ID 0x20) does.
  int sips = 0;
  const auto deadline = Clock::now() + kReplyTimeout;
  while (auto packet = P2osReceive(wire, deadline)) {
    EXPECT_NE((*packet)[3], 0x20);
    sips += (*packet)[3] == 0x32 || (*packet)[3] == 0x33;
  }
  EXPECT_GE(sips, 5);  // a SIP every 100 ms
  wire.Write(P2osCommand(p2os::kEnable, 1));
  wire.Write(P2osCommand(p2os::kVel, 300));
  wire.Write(P2osCommand(p2os::kRVel, -20));
  ASSERT_TRUE(Eventually([&] { return emulator.command().second < 0.0; }));
  EXPECT_NEAR(emulator.command().first, 0.3, 1e-9);
  EXPECT_NEAR(emulator.command().second, -20.0 * kPi / 180.0, 1e-9);
  // processMotorPacket: after the sonars GRIPSTATE, ANPORT, ANALOG, DIGIN, DIGOUT,
  // BATTERYX10 (2), CHARGESTATE, ROTVEL (2, 0.1 deg/s), FAULTFLAGS (2).
  wire.Flush();
  std::optional<Bytes> sip = NextSip(wire);
  ASSERT_TRUE(sip);
  const Bytes& p = *sip;
  const std::size_t after_sonars = 3 + 20 + 3 * std::size_t(p[3 + 19]);
  ASSERT_GE(p.size(), after_sonars + 12 + 2);
  EXPECT_EQ(p[3 + 16] & 0x01, 1);                                    // FLAGS bit 0: motors enabled
  EXPECT_EQ(p[after_sonars + 5] | (p[after_sonars + 6] << 8), 128);  // 12.8 V x 10
  EXPECT_EQ(std::int16_t(p[after_sonars + 8] | (p[after_sonars + 9] << 8)), -200);
  // com2Bytes(VEL2, -5, 5): (0xFB << 8) + 5 = 0xFB05 overflows a short: ARGNINT 1275.
  wire.Write(P2osCommand(p2os::kVel2, std::int16_t(0xFB05)));
  ASSERT_TRUE(Eventually([&] { return emulator.command().second > 0.0; }));
  EXPECT_NEAR(emulator.command().first, 0.0, 1e-9);
  EXPECT_NEAR(emulator.command().second, 0.2 / P2osEmulatorConfig{}.track_m, 1e-9);
  // Disconnect: comInt(CLOSE, 1).
  wire.Write(P2osCommand(p2os::kClose, 1));
  EXPECT_TRUE(Eventually([&] { return !emulator.connected(); }));
}

}  // namespace
}  // namespace pitchlab::hw
