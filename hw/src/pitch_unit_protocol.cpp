#include "pitchlab/hw/pitch_unit_protocol.hpp"

#include <string>

namespace pitchlab::hw::pitch {
namespace {

void Put(std::vector<std::uint8_t>& out, std::uint32_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
}

std::uint32_t Get(const std::vector<std::uint8_t>& in, std::size_t at, int bytes) {
  std::uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= std::uint32_t(in[at + std::size_t(i)]) << (8 * i);
  return v;
}

Result<void> Expect(const Frame& reply, std::uint8_t command, std::size_t payload_bytes) {
  if (reply.command == kErrorReply && !reply.payload.empty()) {
    return Fail(Error::Code::kProtocol,
                "pitch unit error code " + std::to_string(reply.payload[0]));
  }
  if (reply.command != (command | kReplyBit) || reply.payload.size() != payload_bytes) {
    return Fail(Error::Code::kProtocol, "unexpected pitch unit reply " +
                                            std::to_string(reply.command) + " of " +
                                            std::to_string(reply.payload.size()) + " bytes");
  }
  return {};
}

}  // namespace

std::uint16_t Crc16Ccitt(const std::uint8_t* data, std::size_t size) {
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= std::uint16_t(data[i] << 8);
    for (int b = 0; b < 8; ++b) {
      crc = (crc & 0x8000) ? std::uint16_t((crc << 1) ^ 0x1021) : std::uint16_t(crc << 1);
    }
  }
  return crc;
}

std::vector<std::uint8_t> Encode(const Frame& frame) {
  const std::size_t n = std::min(frame.payload.size(), kMaxLen - 1);
  std::vector<std::uint8_t> out;
  out.reserve(3 + n + 2);  // sized up front: growing a 3-byte vector trips GCC 12's -Warray-bounds
  out.push_back(kSync);
  out.push_back(std::uint8_t(1 + n));
  out.push_back(frame.command);
  out.insert(out.end(), frame.payload.begin(), frame.payload.begin() + long(n));
  Put(out, Crc16Ccitt(out.data() + 1, out.size() - 1), 2);
  return out;
}

Frame MoveRequest(std::int16_t step) {
  Frame f{kMove, {}};
  Put(f.payload, std::uint16_t(step), 2);
  return f;
}

Frame EncodeInfo(const Info& info) {
  Frame f{kPing | kReplyBit, {info.version}};
  Put(f.payload, info.step_cdeg, 2);
  Put(f.payload, info.counts_per_rev, 4);
  Put(f.payload, std::uint16_t(info.min_step), 2);
  Put(f.payload, std::uint16_t(info.max_step), 2);
  return f;
}

Frame EncodeStatus(const Status& status) {
  Frame f{kStatus | kReplyBit, {status.flags}};
  Put(f.payload, std::uint16_t(status.target), 2);
  Put(f.payload, std::uint32_t(status.count), 4);
  return f;
}

Result<Info> DecodeInfo(const Frame& reply) {
  if (Result<void> ok = Expect(reply, kPing, 11); !ok) return tl::make_unexpected(ok.error());
  Info info;
  info.version = reply.payload[0];
  info.step_cdeg = std::uint16_t(Get(reply.payload, 1, 2));
  info.counts_per_rev = Get(reply.payload, 3, 4);
  info.min_step = std::int16_t(Get(reply.payload, 7, 2));
  info.max_step = std::int16_t(Get(reply.payload, 9, 2));
  return info;
}

Result<Status> DecodeStatus(const Frame& reply) {
  if (Result<void> ok = Expect(reply, kStatus, 7); !ok) return tl::make_unexpected(ok.error());
  return Status{reply.payload[0], std::int16_t(Get(reply.payload, 1, 2)),
                std::int32_t(Get(reply.payload, 3, 4))};
}

Result<std::int32_t> DecodeEncoder(const Frame& reply) {
  if (Result<void> ok = Expect(reply, kEncoder, 4); !ok) return tl::make_unexpected(ok.error());
  return std::int32_t(Get(reply.payload, 0, 4));
}

Result<std::int16_t> DecodeMoveReply(const Frame& reply) {
  if (Result<void> ok = Expect(reply, kMove, 3); !ok) return tl::make_unexpected(ok.error());
  return std::int16_t(Get(reply.payload, 0, 2));
}

void FrameReader::Feed(const std::uint8_t* bytes, std::size_t size) {
  buffer_.insert(buffer_.end(), bytes, bytes + size);
}

std::optional<Frame> FrameReader::Next() {
  while (!buffer_.empty()) {
    if (buffer_[0] != kSync) {
      buffer_.pop_front();
      ++garbage_bytes_;
      continue;
    }
    if (buffer_.size() < 2) return std::nullopt;
    const std::size_t len = buffer_[1];
    if (len < 1 || len > kMaxLen) {
      buffer_.pop_front();
      ++garbage_bytes_;
      continue;
    }
    const std::size_t total = 2 + len + 2;
    if (buffer_.size() < total) return std::nullopt;
    std::vector<std::uint8_t> bytes(buffer_.begin(), buffer_.begin() + long(total));
    const std::uint16_t crc = Crc16Ccitt(bytes.data() + 1, 1 + len);
    if (crc != std::uint16_t(bytes[total - 2] | (bytes[total - 1] << 8))) {
      buffer_.pop_front();  // resync: a frame may start inside
      ++crc_errors_;
      continue;
    }
    buffer_.erase(buffer_.begin(), buffer_.begin() + long(total));
    return Frame{bytes[2], std::vector<std::uint8_t>(bytes.begin() + 3, bytes.end() - 2)};
  }
  return std::nullopt;
}

}  // namespace pitchlab::hw::pitch
