#pragma once
// The SICK LMS2xx binary telegram protocol: framing, SICK's CRC, measured values, and a
// resynchronising reader. Pure functions on bytes: no I/O, so decoders can be fuzzed.
//
// Telegram: STX(02) ADR LEN(2, LE) CMD DATA... CRC(2, LE). LEN counts CMD + DATA (a reply's
// trailing status byte is part of DATA). Replies come from ADR 0x80 with CMD | 0x80, each
// preceded by one ACK (06) or NAK (15) byte.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "pitchlab/sensors/laser_line.hpp"
#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::hw::lms200 {

constexpr std::uint8_t kStx = 0x02;
constexpr std::uint8_t kAck = 0x06;
constexpr std::uint8_t kNak = 0x15;
constexpr std::uint8_t kHostAddress = 0x00;   ///< requests go to device address 0
constexpr std::uint8_t kReplyAddress = 0x80;  ///< replies come from 0x80
constexpr std::uint8_t kReplyBit = 0x80;      ///< reply command = request command | 0x80
constexpr std::size_t kMaxDataBytes = 1024;   ///< longest CMD + DATA accepted (801 values fit)

/// Request commands the driver uses.
enum Command : std::uint8_t {
  kReset = 0x10,           ///< re-initialise; reply 0x91, then the power-on telegram
  kSwitchMode = 0x20,      ///< operating mode / baud rate; reply 0xA0
  kRequestValues = 0x30,   ///< measured values (0x01 = one full scan); reply 0xB0
  kRequestStatus = 0x31,   ///< status; reply 0xB1 (kStatusBlockBytes + status byte)
  kRequestErrors = 0x32,   ///< error list (type, number pairs); reply 0xB2
  kRequestType = 0x3A,     ///< type string ("LMS200;30106"); reply 0xBA
  kSwitchVariant = 0x3B,   ///< field of view + resolution; reply 0xBB
  kRequestConfig = 0x74,   ///< configuration block; reply 0xF4
  kConfigure = 0x77,       ///< write configuration block (setup mode); reply 0xF7
  kPowerOn = 0x90,         ///< unsolicited power-on telegram (a reply-side command)
  kResetAck = 0x91,        ///< the reply to kReset (not kReset | 0x80, which is kPowerOn)
  kMeanValues = 0xB6,      ///< streamed mean of n scans (mode 0x26)
  kSubrangeValues = 0xB7,  ///< streamed sub-range of a scan (mode 0x27)
};

/// Operating-mode codes for kSwitchMode.
enum Mode : std::uint8_t {
  kModeSetup = 0x00,         ///< installation mode (needs the password "SICK_LMS")
  kModeContinuous = 0x24,    ///< stream all measured values
  kModeOnRequest = 0x25,     ///< measured values only on request
  kModeMeanValues = 0x26,    ///< stream the mean of n scans (data: n, 2..250)
  kModeSubrange = 0x27,      ///< stream values first..last (data: two LE16 indices, from 1)
  kModePartialScans = 0x2A,  ///< stream the interlaced partial scans one by one
  kModeBaud38400 = 0x40,
  kModeBaud19200 = 0x41,
  kModeBaud9600 = 0x42,
  kModeBaud500k = 0x48,
};

/// The configuration block (kRequestConfig reply data without its status byte; kConfigure
/// request data): blocks A..A4, 34 bytes. Offsets of the bytes the clients touch (layout as
/// docs/hardware_interop.md records it from independent LMS2xx drivers).
constexpr std::size_t kConfigBlockBytes = 34;
/// The shorter block the LMS2xx family also takes: blocks A..A3 without the dazzling
/// evaluation word (ARIA's ArLMS2xx builds these 32 bytes); applied as a prefix of the full one.
constexpr std::size_t kConfigShortBlockBytes = 32;
constexpr std::size_t kConfigAvailabilityIndex = 4;  ///< block C
/// Block C bits (sicktoolbox's SICK_FLAG_AVAILABILITY_*).
constexpr std::uint8_t kAvailabilityHigh = 0x01;             ///< highest availability
constexpr std::uint8_t kAvailabilityRealTimeIndices = 0x02;  ///< scan index in each B0/B6/B7
constexpr std::uint8_t kAvailabilityDazzleNoEffect = 0x04;   ///< dazzle: outputs unaffected
constexpr std::size_t kConfigMeasuringModeIndex = 5;         ///< block D: 0..2 = 8 m / 80 m modes
constexpr std::size_t kConfigUnitsIndex = 6;                 ///< block E: 0 = cm, 1 = mm
/// The status block (kRequestStatus reply data without its status byte), 152 bytes, and the
/// offsets in it of the fields clients read (data index: the telegram's byte after CMD is 0).
constexpr std::size_t kStatusBlockBytes = 152;
constexpr std::size_t kStatusVersionIndex = 0;          ///< 7 characters, e.g. "V02.10 "
constexpr std::size_t kStatusOperatingModeIndex = 7;    ///< kModeSetup / 0x24 / 0x25
constexpr std::size_t kStatusDeviceStatusIndex = 8;     ///< 0 = no error
constexpr std::size_t kStatusMeasuringModeIndex = 101;  ///< as the configuration's block D
constexpr std::size_t kStatusScanAngleIndex = 106;      ///< field of view [deg], LE 16 bit
constexpr std::size_t kStatusResolutionIndex = 108;     ///< [0.01 deg], LE 16 bit
constexpr std::size_t kStatusUnitsIndex = 121;          ///< 0 = cm, 1 = mm
/// Special measured-value codes (13-bit).
constexpr std::uint16_t kCodeNoReturn = 8191;  ///< invalid / no measurement
constexpr std::uint16_t kCodeDazzled = 8190;
constexpr std::uint16_t kCodeOverRange = 8183;  ///< beyond the maximum (cm mode)
constexpr std::uint16_t kFirstSpecialCode = 8183;

/// SICK's 16-bit CRC (poly 0x8005, init 0, over STX .. last data byte). Not CRC-16/ARC.
std::uint16_t Crc16(const std::uint8_t* data, std::size_t size);

/// One telegram. `data` includes a reply's trailing status byte.
struct Telegram {
  std::uint8_t address = kHostAddress;
  std::uint8_t command = 0;
  std::vector<std::uint8_t> data;

  /// The reply status byte (last data byte); 0 when there is no data.
  std::uint8_t status() const { return data.empty() ? 0 : data.back(); }
  bool operator==(const Telegram& o) const {
    return address == o.address && command == o.command && data == o.data;
  }
};

/// The bytes of `telegram` with its length and CRC.
std::vector<std::uint8_t> Encode(const Telegram& telegram);
/// Exactly one telegram from `bytes`; kProtocol naming what is wrong (framing, length, CRC).
[[nodiscard]] Result<Telegram> Decode(const std::uint8_t* bytes, std::size_t size);

/// Baud-rate code for kSwitchMode, or nullopt for a rate the LMS200 cannot do.
std::optional<std::uint8_t> BaudModeCode(int baud);

/// Request builders for every command the driver sends.
Telegram SwitchModeRequest(std::uint8_t mode);
Telegram SetupModeRequest();  ///< kSwitchMode 0x00 with the password "SICK_LMS"
Telegram SingleScanRequest();
Telegram TypeRequest();
Telegram StatusRequest();
Telegram ErrorsRequest();
Telegram VariantRequest(int fov_deg, int resolution_cdeg);  ///< e.g. (180, 50)
Telegram ConfigRequest();
Telegram ConfigureRequest(const std::vector<std::uint8_t>& block);

/// Measured-value units from bits 14-15 of the count word.
enum class Units : std::uint8_t { kCm = 0, kMm = 1, kDm = 2 };

/// The payload of a 0xB0 reply.
struct MeasuredValues {
  Units units = Units::kCm;
  bool partial = false;               ///< bit 13: a partial (interlaced) scan
  std::vector<std::uint16_t> values;  ///< 13-bit readings (flag bits 13-15 stripped)
  /// The real-time scan index (mirror revolutions mod 256), one byte between the values and the
  /// status byte while block C's kAvailabilityRealTimeIndices is set (sicktoolbox
  /// _parseSickScanProfileB0/B6/B7 read it there).
  std::optional<std::uint8_t> real_time_index;
  std::uint8_t status = 0;  ///< the telegram's status byte
};

/// Decodes a 0xB0 telegram (with or without the real-time index byte); kProtocol when the
/// command, count or length do not agree.
[[nodiscard]] Result<MeasuredValues> DecodeMeasuredValues(const Telegram& telegram);
/// Builds a 0xB0 reply telegram.
Telegram EncodeMeasuredValues(const MeasuredValues& values);
/// Builds a 0xB6 telegram: the number of scans averaged, then the values as in 0xB0.
Telegram EncodeMeanValues(int samples, const MeasuredValues& values);
/// Builds a 0xB7 telegram: first and last index (from 1, LE16 each), then the values as in 0xB0.
Telegram EncodeSubrangeValues(int first, int last, const MeasuredValues& values);

/// One reading as (range [m] or NaN, status): 8191 no return, 8190 dazzled, 8183 over range,
/// other codes >= 8183 no return; else value x unit.
std::pair<float, sensors::ReadingStatus> DecodeReading(std::uint16_t value, Units units);
/// The 13-bit value for a reading (inverse of DecodeReading; valid ranges that would land on a
/// special code are sent as over range).
std::uint16_t EncodeReading(float range_m, sensors::ReadingStatus status, Units units);

/// Reader counters: what was skipped while resynchronising.
struct ReaderStats {
  std::size_t telegrams = 0;  ///< good telegrams
  std::size_t acks = 0;
  std::size_t naks = 0;
  std::size_t crc_errors = 0;     ///< framed telegrams whose CRC did not match
  std::size_t garbage_bytes = 0;  ///< bytes skipped outside any telegram
};

/// What the reader found next in the byte stream.
struct ReaderEvent {
  enum class Kind { kTelegram, kAck, kNak } kind = Kind::kTelegram;
  Telegram telegram;  ///< for kTelegram
};

/// Turns a byte stream into telegrams and ACK/NAK bytes. Garbage, partial telegrams, CRC errors
/// and bad lengths are skipped (one byte at a time, so a telegram hidden behind a false STX is
/// still found) and counted. `reply_address_bit` selects the addresses accepted: 0x80 for a host
/// reading replies, 0x00 for a device reading requests.
class TelegramReader {
 public:
  explicit TelegramReader(std::uint8_t reply_address_bit = kReplyAddress);
  /// Appends received bytes.
  void Feed(const std::uint8_t* bytes, std::size_t size);
  /// The next complete item, or nullopt when more bytes are needed.
  std::optional<ReaderEvent> Next();
  /// Drops everything buffered (counted as garbage).
  void Clear();
  /// Bytes buffered and not yet consumed.
  std::size_t buffered() const { return buffer_.size(); }
  const ReaderStats& stats() const { return stats_; }

 private:
  std::uint8_t address_bit_;
  std::deque<std::uint8_t> buffer_;
  ReaderStats stats_;
};

}  // namespace pitchlab::hw::lms200
