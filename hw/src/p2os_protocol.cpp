#include "pitchlab/hw/p2os_protocol.hpp"

#include <cstdlib>

namespace pitchlab::hw::p2os {
namespace {

void PutLe(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(std::uint8_t(v & 0xFF));
  out.push_back(std::uint8_t(v >> 8));
}

std::uint16_t GetLe(const std::vector<std::uint8_t>& in, std::size_t at) {
  return std::uint16_t(in[at] | (in[at + 1] << 8));
}

// Offsets in the standard SIP payload (ARCOS manual order).
constexpr std::size_t kXPos = 1, kYPos = 3, kThPos = 5, kLVelAt = 7, kRVelAt = 9, kBattery = 11,
                      kStall = 12, kFlagsAt = 16, kSonarCount = 19, kRotVelAfterSonars = 8;
constexpr std::size_t kMinSip = 20;

}  // namespace

std::uint16_t Checksum(const std::uint8_t* payload, std::size_t size) {
  std::uint32_t sum = 0;
  std::size_t i = 0;
  for (; i + 1 < size; i += 2) sum = (sum + ((payload[i] << 8) | payload[i + 1])) & 0xFFFF;
  if (i < size) sum ^= payload[i];
  return std::uint16_t(sum);
}

std::vector<std::uint8_t> Encode(const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out;
  out.reserve(payload.size() + 5);
  out.push_back(kHeader0);
  out.push_back(kHeader1);
  out.push_back(std::uint8_t(payload.size() + 2));
  for (std::uint8_t b : payload) out.push_back(b);
  const std::uint16_t c = Checksum(payload.data(), payload.size());
  out.push_back(std::uint8_t(c >> 8));
  out.push_back(std::uint8_t(c & 0xFF));
  return out;
}

std::vector<std::uint8_t> CommandPacket(std::uint8_t command) { return Encode({command}); }

std::vector<std::uint8_t> CommandPacket(std::uint8_t command, int argument) {
  const unsigned magnitude = unsigned(std::min(std::abs(argument), 0x7FFF));
  return Encode({command, argument < 0 ? kArgNegInt : kArgInt, std::uint8_t(magnitude & 0xFF),
                 std::uint8_t(magnitude >> 8)});
}

std::vector<std::uint8_t> Sync2Reply(const std::string& name, const std::string& type,
                                     const std::string& subtype) {
  std::vector<std::uint8_t> payload = {kSync2};
  for (const std::string* s : {&name, &type, &subtype}) {
    payload.insert(payload.end(), s->begin(), s->end());
    payload.push_back(0);
  }
  return Encode(payload);
}

Result<int> CommandArgument(const std::vector<std::uint8_t>& payload) {
  if (payload.size() != 4 || (payload[1] != kArgInt && payload[1] != kArgNegInt)) {
    return Fail(Error::Code::kProtocol, "command without an integer argument");
  }
  const int magnitude = GetLe(payload, 2);
  return payload[1] == kArgNegInt ? -magnitude : magnitude;
}

std::vector<std::uint8_t> EncodeSip(const Sip& sip) {
  std::vector<std::uint8_t> p = {sip.moving ? kSipMoving : kSipStopped};
  PutLe(p, sip.x_raw & 0x7FFF);
  PutLe(p, sip.y_raw & 0x7FFF);
  PutLe(p, std::uint16_t(sip.theta_raw));
  PutLe(p, std::uint16_t(sip.left_mmps));
  PutLe(p, std::uint16_t(sip.right_mmps));
  p.push_back(sip.battery_dv);
  PutLe(p, std::uint16_t((sip.stall_left ? 0x01 : 0) | (sip.stall_right ? 0x100 : 0)));
  PutLe(p, 0);  // CONTROL
  PutLe(p, sip.flags);
  p.push_back(0);                                // COMPASS
  p.push_back(0);                                // no sonar readings
  p.insert(p.end(), {0, 0, 0, 0, 0});            // GRIP_STATE, ANPORT, ANALOG, DIGIN, DIGOUT
  PutLe(p, sip.battery_dv);                      // BATTERYX10: volts x 10, 16 bit
  p.push_back(0);                                // CHARGESTATE
  PutLe(p, std::uint16_t(sip.rotvel_ddps));
  PutLe(p, 0);  // FAULTFLAGS
  return p;
}

Result<Sip> DecodeSip(const std::vector<std::uint8_t>& p) {
  if (p.empty() || (p[0] != kSipStopped && p[0] != kSipMoving)) {
    return Fail(Error::Code::kProtocol, "not a standard SIP");
  }
  if (p.size() < kMinSip) return Fail(Error::Code::kProtocol, "SIP too short");
  Sip sip;
  sip.moving = p[0] == kSipMoving;
  sip.x_raw = GetLe(p, kXPos) & 0x7FFF;
  sip.y_raw = GetLe(p, kYPos) & 0x7FFF;
  sip.theta_raw = std::int16_t(GetLe(p, kThPos));
  sip.left_mmps = std::int16_t(GetLe(p, kLVelAt));
  sip.right_mmps = std::int16_t(GetLe(p, kRVelAt));
  sip.battery_dv = p[kBattery];
  const std::uint16_t stall = GetLe(p, kStall);
  sip.stall_left = stall & 0x01;
  sip.stall_right = stall & 0x100;
  sip.flags = GetLe(p, kFlagsAt);
  // Sonar readings (3 bytes each) sit between the count and the rest.
  const std::size_t rotvel_at =
      kSonarCount + 1 + 3 * std::size_t(p[kSonarCount]) + kRotVelAfterSonars;
  if (p.size() >= rotvel_at + 2) sip.rotvel_ddps = std::int16_t(GetLe(p, rotvel_at));
  return sip;
}

void PacketReader::Feed(const std::uint8_t* bytes, std::size_t size) {
  buffer_.insert(buffer_.end(), bytes, bytes + size);
}

std::optional<std::vector<std::uint8_t>> PacketReader::Next() {
  while (!buffer_.empty()) {
    if (buffer_[0] != kHeader0 || (buffer_.size() >= 2 && buffer_[1] != kHeader1)) {
      buffer_.pop_front();
      ++garbage_bytes_;
      continue;
    }
    if (buffer_.size() < 3) return std::nullopt;
    const std::size_t count = buffer_[2];
    if (count < 3 || count > kMaxPayload + 2) {
      buffer_.pop_front();
      ++garbage_bytes_;
      continue;
    }
    if (buffer_.size() < 3 + count) return std::nullopt;
    std::vector<std::uint8_t> payload(buffer_.begin() + 3, buffer_.begin() + long(1 + count));
    const std::uint16_t sent = std::uint16_t((buffer_[1 + count] << 8) | buffer_[2 + count]);
    if (Checksum(payload.data(), payload.size()) != sent) {
      buffer_.pop_front();
      ++checksum_errors_;
      continue;
    }
    buffer_.erase(buffer_.begin(), buffer_.begin() + long(3 + count));
    return payload;
  }
  return std::nullopt;
}

}  // namespace pitchlab::hw::p2os
