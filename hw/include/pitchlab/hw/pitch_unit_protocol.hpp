#pragma once
// The pitch unit's framed binary protocol (docs/pitch_unit_protocol.md): framing, CRC and a
// resynchronising reader. Pure functions on bytes, fuzzable.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::hw::pitch {

constexpr std::uint8_t kSync = 0xA5;
constexpr std::uint8_t kReplyBit = 0x80;
constexpr std::size_t kMaxLen = 64;  ///< longest CMD + PAYLOAD

enum Command : std::uint8_t { kPing = 0x01, kMove = 0x02, kEncoder = 0x03, kStatus = 0x04 };
constexpr std::uint8_t kErrorReply = 0xFF;
enum ErrorCode : std::uint8_t { kBadCrc = 1, kUnknownCommand = 2, kBadLength = 3 };
enum Flags : std::uint8_t { kMoving = 1, kSettled = 2, kFault = 4, kClamped = 8 };

/// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF): "123456789" -> 0x29B1.
std::uint16_t Crc16Ccitt(const std::uint8_t* data, std::size_t size);

struct Frame {
  std::uint8_t command = 0;
  std::vector<std::uint8_t> payload;
  bool operator==(const Frame& o) const { return command == o.command && payload == o.payload; }
};

/// The bytes of `frame`; the payload must be at most kMaxLen - 1 bytes (asserted by truncation).
std::vector<std::uint8_t> Encode(const Frame& frame);

/// Device description from a PING reply.
struct Info {
  std::uint8_t version = 1;
  std::uint16_t step_cdeg = 45;
  std::uint32_t counts_per_rev = 36000;
  std::int16_t min_step = 0, max_step = 0;
};
/// Status from a STATUS reply.
struct Status {
  std::uint8_t flags = 0;
  std::int16_t target = 0;
  std::int32_t count = 0;
};

Frame MoveRequest(std::int16_t step);
Frame EncodeInfo(const Info& info);        ///< the PING reply
Frame EncodeStatus(const Status& status);  ///< the STATUS reply
/// Parsers of replies; kProtocol when command or length are wrong.
[[nodiscard]] Result<Info> DecodeInfo(const Frame& reply);
[[nodiscard]] Result<Status> DecodeStatus(const Frame& reply);
[[nodiscard]] Result<std::int32_t> DecodeEncoder(const Frame& reply);
[[nodiscard]] Result<std::int16_t> DecodeMoveReply(const Frame& reply);

/// Frames from a byte stream; garbage, bad lengths and CRC errors are skipped and counted.
class FrameReader {
 public:
  void Feed(const std::uint8_t* bytes, std::size_t size);
  std::optional<Frame> Next();
  void Clear() {
    garbage_bytes_ += buffer_.size();
    buffer_.clear();
  }
  std::size_t crc_errors() const { return crc_errors_; }
  std::size_t garbage_bytes() const { return garbage_bytes_; }

 private:
  std::deque<std::uint8_t> buffer_;
  std::size_t crc_errors_ = 0, garbage_bytes_ = 0;
};

}  // namespace pitchlab::hw::pitch
