#pragma once
// The Pioneer P2OS / ARCOS client-server protocol: packets, checksum, commands and the standard
// server information packet (SIP). Pure functions on bytes, fuzzable.
//
// Packet: FA FB N PAYLOAD(N-2) CHECKSUM(2, high byte first); N counts payload + checksum.
// Checksum: the payload as big-endian 16-bit words summed (mod 2^16), an odd last byte XORed in.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::hw::p2os {

constexpr std::uint8_t kHeader0 = 0xFA;
constexpr std::uint8_t kHeader1 = 0xFB;
constexpr std::size_t kMaxPayload = 200;

/// Client commands (first payload byte).
enum Command : std::uint8_t {
  kSync0 = 0,
  kSync1 = 1,
  kSync2 = 2,  ///< connection handshake, echoed by the robot
  kPulse = 0,  ///< keep-alive (same number as SYNC0 once connected)
  kOpen = 1,
  kClose = 2,
  kSetO = 7,     ///< reset odometry to the origin
  kEnable = 4,   ///< motors on (arg 1) / off (arg 0)
  kVel = 11,     ///< forward speed [mm/s]
  kConfig = 18,  ///< request a CONFIG packet (not emulated: clients fall back to their tables)
  kRVel = 21,    ///< rotational speed [deg/s]
  /// Auxiliary power output: argument bits 8-15 the output, bits 0-7 on (1) / off (0) (ARIA's
  /// com2Bytes(31, port, state); its ArLaserConnector switches the laser with port 11).
  kAuxPower = 31,
  kSonar = 28,  ///< sonars on (arg 1) / off (arg 0)
  kStop = 29,   ///< stop moving, motors stay enabled
  kVel2 = 32,   ///< wheel speeds: argument bits 8-15 left, 0-7 right, signed, kVel2Unit each
  kEStop = 55,
};
/// Argument type bytes.
constexpr std::uint8_t kArgInt = 0x3B;
constexpr std::uint8_t kArgNegInt = 0x1B;
/// SIP types: standard SIPs are 0x32 (motors stopped) and 0x33 (moving).
constexpr std::uint8_t kSipStopped = 0x32;
constexpr std::uint8_t kSipMoving = 0x33;

/// The auxiliary power output that feeds the laser (ARIA ArLaserConnector: "legacy method to
/// turn on LRF power", com2Bytes(31, 11, 1)).
constexpr int kLaserPowerOutput = 11;

std::uint16_t Checksum(const std::uint8_t* payload, std::size_t size);
/// FA FB N payload checksum.
std::vector<std::uint8_t> Encode(const std::vector<std::uint8_t>& payload);
/// A command without argument, with an integer argument (sign in the type byte), or the SYNC2
/// reply with the robot's name, class and subclass strings.
std::vector<std::uint8_t> CommandPacket(std::uint8_t command);
std::vector<std::uint8_t> CommandPacket(std::uint8_t command, int argument);
std::vector<std::uint8_t> Sync2Reply(const std::string& name, const std::string& type,
                                     const std::string& subtype);
/// The integer argument of a command payload; kProtocol when it has none.
[[nodiscard]] Result<int> CommandArgument(const std::vector<std::uint8_t>& payload);

/// The fields of a standard SIP pitchlab uses.
struct Sip {
  bool moving = false;
  std::uint16_t x_raw = 0, y_raw = 0;          ///< XPOS, YPOS [mm], 15-bit, wrapping
  std::int16_t theta_raw = 0;                  ///< THPOS [4096/rev]
  std::int16_t left_mmps = 0, right_mmps = 0;  ///< wheel velocities [mm/s]
  std::uint8_t battery_dv = 0;                 ///< battery [0.1 V]
  bool stall_left = false, stall_right = false;
  std::uint16_t flags = 0;       ///< bit 0: motors enabled
  std::int16_t rotvel_ddps = 0;  ///< rotational velocity [0.1 deg/s]
};
/// Standard SIP payload (type .. fault flags, no sonars).
std::vector<std::uint8_t> EncodeSip(const Sip& sip);
/// Decodes a standard SIP payload; kProtocol when not a SIP or too short.
[[nodiscard]] Result<Sip> DecodeSip(const std::vector<std::uint8_t>& payload);

/// Packets from a byte stream; bad checksums and garbage are skipped and counted.
class PacketReader {
 public:
  void Feed(const std::uint8_t* bytes, std::size_t size);
  /// The next payload (without header, count and checksum).
  std::optional<std::vector<std::uint8_t>> Next();
  void Clear() {
    garbage_bytes_ += buffer_.size();
    buffer_.clear();
  }
  std::size_t checksum_errors() const { return checksum_errors_; }
  std::size_t garbage_bytes() const { return garbage_bytes_; }

 private:
  std::deque<std::uint8_t> buffer_;
  std::size_t checksum_errors_ = 0, garbage_bytes_ = 0;
};

}  // namespace pitchlab::hw::p2os
