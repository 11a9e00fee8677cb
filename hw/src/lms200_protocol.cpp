#include "pitchlab/hw/lms200_protocol.hpp"

#include <cmath>
#include <limits>

namespace pitchlab::hw::lms200 {
namespace {

constexpr std::size_t kHeaderBytes = 4;  // STX, ADR, LEN low, LEN high
constexpr std::size_t kCrcBytes = 2;

void PutU16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(std::uint8_t(v & 0xFF));
  out.push_back(std::uint8_t(v >> 8));
}

std::uint16_t GetU16(const std::uint8_t* p) { return std::uint16_t(p[0] | (p[1] << 8)); }

std::string Hex(unsigned v) {
  static const char* digits = "0123456789ABCDEF";
  return std::string("0x") + digits[(v >> 4) & 0xF] + digits[v & 0xF];
}

double UnitM(Units units) {
  switch (units) {
    case Units::kMm:
      return 0.001;
    case Units::kDm:
      return 0.1;
    case Units::kCm:
      break;
  }
  return 0.01;
}

}  // namespace

std::uint16_t Crc16(const std::uint8_t* data, std::size_t size) {
  // The LMS2xx manual's routine: a shift register over the stream, XORed each step with the
  // current and previous byte.
  std::uint16_t crc = 0;
  std::uint8_t previous = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const std::uint8_t current = data[i];
    if (crc & 0x8000) {
      crc = std::uint16_t((crc & 0x7FFF) << 1);
      crc ^= 0x8005;
    } else {
      crc = std::uint16_t(crc << 1);
    }
    crc ^= std::uint16_t(current | (previous << 8));
    previous = current;
  }
  return crc;
}

std::vector<std::uint8_t> Encode(const Telegram& telegram) {
  std::vector<std::uint8_t> out;
  out.reserve(kHeaderBytes + 1 + telegram.data.size() + kCrcBytes);
  out.push_back(kStx);
  out.push_back(telegram.address);
  PutU16(out, std::uint16_t(1 + telegram.data.size()));
  out.push_back(telegram.command);
  out.insert(out.end(), telegram.data.begin(), telegram.data.end());
  PutU16(out, Crc16(out.data(), out.size()));
  return out;
}

Result<Telegram> Decode(const std::uint8_t* bytes, std::size_t size) {
  if (size < kHeaderBytes + 1 + kCrcBytes) {
    return Fail(Error::Code::kProtocol, "telegram of " + std::to_string(size) + " bytes is short");
  }
  if (bytes[0] != kStx) return Fail(Error::Code::kProtocol, "telegram does not start with STX");
  const std::size_t length = GetU16(bytes + 2);
  if (length < 1 || length > kMaxDataBytes) {
    return Fail(Error::Code::kProtocol, "telegram length " + std::to_string(length) + " invalid");
  }
  if (size != kHeaderBytes + length + kCrcBytes) {
    return Fail(Error::Code::kProtocol, "telegram length " + std::to_string(length) +
                                            " does not match its " + std::to_string(size) +
                                            " bytes");
  }
  const std::uint16_t crc = Crc16(bytes, kHeaderBytes + length);
  if (crc != GetU16(bytes + kHeaderBytes + length)) {
    return Fail(Error::Code::kProtocol, "telegram CRC mismatch");
  }
  Telegram t;
  t.address = bytes[1];
  t.command = bytes[4];
  t.data.assign(bytes + kHeaderBytes + 1, bytes + kHeaderBytes + length);
  return t;
}

std::optional<std::uint8_t> BaudModeCode(int baud) {
  switch (baud) {
    case 9600:
      return kModeBaud9600;
    case 19200:
      return kModeBaud19200;
    case 38400:
      return kModeBaud38400;
    case 500000:
      return kModeBaud500k;
    default:
      return std::nullopt;
  }
}

Telegram SwitchModeRequest(std::uint8_t mode) { return {kHostAddress, kSwitchMode, {mode}}; }

Telegram SetupModeRequest() {
  Telegram t{kHostAddress, kSwitchMode, {kModeSetup}};
  for (char c : std::string("SICK_LMS")) t.data.push_back(std::uint8_t(c));
  return t;
}

Telegram SingleScanRequest() { return {kHostAddress, kRequestValues, {0x01}}; }
Telegram TypeRequest() { return {kHostAddress, kRequestType, {}}; }
Telegram StatusRequest() { return {kHostAddress, kRequestStatus, {}}; }
Telegram ErrorsRequest() { return {kHostAddress, kRequestErrors, {}}; }

Telegram VariantRequest(int fov_deg, int resolution_cdeg) {
  Telegram t{kHostAddress, kSwitchVariant, {}};
  PutU16(t.data, std::uint16_t(fov_deg));
  PutU16(t.data, std::uint16_t(resolution_cdeg));
  return t;
}

Telegram ConfigRequest() { return {kHostAddress, kRequestConfig, {}}; }

Telegram ConfigureRequest(const std::vector<std::uint8_t>& block) {
  return {kHostAddress, kConfigure, block};
}

Result<MeasuredValues> DecodeMeasuredValues(const Telegram& telegram) {
  if (telegram.command != (kRequestValues | kReplyBit)) {
    return Fail(Error::Code::kProtocol,
                "telegram " + Hex(telegram.command) + " is not a measured-value reply");
  }
  const std::vector<std::uint8_t>& d = telegram.data;
  if (d.size() < 3) return Fail(Error::Code::kProtocol, "measured-value reply too short");
  const std::uint16_t word = GetU16(d.data());
  const std::size_t count = word & 0x03FF;
  const bool indexed = d.size() == 2 + 2 * count + 2;
  if (d.size() != 2 + 2 * count + 1 && !indexed) {
    return Fail(Error::Code::kProtocol, "measured-value reply says " + std::to_string(count) +
                                            " values but carries " + std::to_string(d.size()) +
                                            " bytes");
  }
  MeasuredValues mv;
  const unsigned unit_bits = (word >> 14) & 0x3;
  if (unit_bits == 3) return Fail(Error::Code::kProtocol, "measured values with unit code 3");
  mv.units = Units(unit_bits);
  mv.partial = (word >> 13) & 0x1;
  mv.values.resize(count);
  for (std::size_t i = 0; i < count; ++i) mv.values[i] = GetU16(&d[2 + 2 * i]) & 0x1FFF;
  if (indexed) mv.real_time_index = d[d.size() - 2];
  mv.status = d.back();
  return mv;
}

namespace {

// Count word, values, the optional real-time index and the status: the tail every
// measured-value telegram (B0, B6, B7) shares.
void PutValues(std::vector<std::uint8_t>& out, const MeasuredValues& values) {
  const std::uint16_t word =
      std::uint16_t((values.values.size() & 0x03FF) | (values.partial ? 1u << 13 : 0u) |
                    (unsigned(values.units) << 14));
  PutU16(out, word);
  for (std::uint16_t v : values.values) PutU16(out, std::uint16_t(v & 0x1FFF));
  if (values.real_time_index) out.push_back(*values.real_time_index);
  out.push_back(values.status);
}

}  // namespace

Telegram EncodeMeasuredValues(const MeasuredValues& values) {
  Telegram t{kReplyAddress, kRequestValues | kReplyBit, {}};
  PutValues(t.data, values);
  return t;
}

Telegram EncodeMeanValues(int samples, const MeasuredValues& values) {
  Telegram t{kReplyAddress, kMeanValues, {std::uint8_t(samples)}};
  PutValues(t.data, values);
  return t;
}

Telegram EncodeSubrangeValues(int first, int last, const MeasuredValues& values) {
  Telegram t{kReplyAddress, kSubrangeValues, {}};
  PutU16(t.data, std::uint16_t(first));
  PutU16(t.data, std::uint16_t(last));
  PutValues(t.data, values);
  return t;
}

std::pair<float, sensors::ReadingStatus> DecodeReading(std::uint16_t value, Units units) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  value &= 0x1FFF;
  if (value == kCodeDazzled) return {kNaN, sensors::ReadingStatus::kDazzled};
  if (value == kCodeOverRange) return {kNaN, sensors::ReadingStatus::kOverRange};
  if (value >= kFirstSpecialCode) return {kNaN, sensors::ReadingStatus::kNoReturn};
  return {float(value * UnitM(units)), sensors::ReadingStatus::kValid};
}

std::uint16_t EncodeReading(float range_m, sensors::ReadingStatus status, Units units) {
  switch (status) {
    case sensors::ReadingStatus::kNoReturn:
      return kCodeNoReturn;
    case sensors::ReadingStatus::kDazzled:
      return kCodeDazzled;
    case sensors::ReadingStatus::kOverRange:
      return kCodeOverRange;
    case sensors::ReadingStatus::kValid:
      break;
  }
  if (!std::isfinite(range_m) || range_m < 0.0f) return kCodeNoReturn;
  const double counts = std::round(double(range_m) / UnitM(units));
  if (counts >= kFirstSpecialCode) return kCodeOverRange;
  return std::uint16_t(counts);
}

TelegramReader::TelegramReader(std::uint8_t reply_address_bit)
    : address_bit_(reply_address_bit & 0x80) {}

void TelegramReader::Feed(const std::uint8_t* bytes, std::size_t size) {
  buffer_.insert(buffer_.end(), bytes, bytes + size);
}

void TelegramReader::Clear() {
  stats_.garbage_bytes += buffer_.size();
  buffer_.clear();
}

std::optional<ReaderEvent> TelegramReader::Next() {
  while (!buffer_.empty()) {
    const std::uint8_t head = buffer_.front();
    if (head == kAck || head == kNak) {
      buffer_.pop_front();
      ReaderEvent event;
      event.kind = head == kAck ? ReaderEvent::Kind::kAck : ReaderEvent::Kind::kNak;
      ++(head == kAck ? stats_.acks : stats_.naks);
      return event;
    }
    if (head != kStx) {
      buffer_.pop_front();
      ++stats_.garbage_bytes;
      continue;
    }
    // A plausible header: right address side and a length the device can send.
    if (buffer_.size() >= 2 && (buffer_[1] & 0x80) != address_bit_) {
      buffer_.pop_front();
      ++stats_.garbage_bytes;
      continue;
    }
    if (buffer_.size() < kHeaderBytes) return std::nullopt;
    const std::size_t length = std::size_t(buffer_[2]) | (std::size_t(buffer_[3]) << 8);
    if (length < 1 || length > kMaxDataBytes) {
      buffer_.pop_front();
      ++stats_.garbage_bytes;
      continue;
    }
    const std::size_t total = kHeaderBytes + length + kCrcBytes;
    if (buffer_.size() < total) return std::nullopt;  // partial: wait for the rest
    std::vector<std::uint8_t> frame(buffer_.begin(), buffer_.begin() + long(total));
    Result<Telegram> telegram = Decode(frame.data(), frame.size());
    if (!telegram) {
      // Drop only the STX: a real telegram may start inside this false frame.
      buffer_.pop_front();
      ++stats_.crc_errors;
      continue;
    }
    buffer_.erase(buffer_.begin(), buffer_.begin() + long(total));
    ++stats_.telegrams;
    ReaderEvent event;
    event.telegram = std::move(*telegram);
    return event;
  }
  return std::nullopt;
}

}  // namespace pitchlab::hw::lms200
