#include "pitchlab/hw/lms200_emulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

namespace pitchlab::hw {
namespace {

using lms200::Telegram;
constexpr std::uint8_t kStatusOk = 0x00;

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr char kVersion[] = "V02.10 ";  // 7 characters, as the status block holds them

std::string PowerOnText(const std::string& type) { return type + ";" + kVersion; }

// A telegram whose characters stop coming is dropped, as the LMS's receiver drops one whose
// characters come too far apart (Player's sicklms200 writes a telegram byte by byte because the
// device tolerates only ~55 us between characters at 500 kBd). Without it a false header (line
// noise, a driver killed mid-write) claiming up to 1024 bytes swallowed every later request, and
// the device answered them all at once when enough bytes had come, a baud switch among them
// (an independent client's check, session 52). On a pty the client's scheduler sets the gaps
// within one write, not the line, so the emulator allows far more than the device: 100 ms,
// still a tenth of the 1 s a driver waits for a reply before it tries again.
constexpr double kCharacterTimeout_s = 0.1;

}  // namespace

Lms200Emulator::Lms200Emulator(const Lms200EmulatorConfig& config, LineSourceFn source,
                               std::string link_path)
    : EmulatedDevice("lms200", config.power_on_baud, std::move(link_path)),
      config_(config),
      source_(std::move(source)),
      current_(config.lms) {
  current_.Validate();
  config_block_.assign(lms200::kConfigBlockBytes, 0);
  OnPowerOn();
  Start();
}

Lms200Emulator::~Lms200Emulator() { Stop(); }

sensors::Lms200Config Lms200Emulator::current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return current_;
}

std::size_t Lms200Emulator::scans_sent() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return scans_sent_;
}

void Lms200Emulator::OnPowerOn() {
  // A power cycle: back to the power-on rate and settings, then the power-on telegram.
  set_baud(config_.power_on_baud);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    current_ = config_.lms;
  }
  config_block_[lms200::kConfigUnitsIndex] =
      config_.lms.range_mode == sensors::Lms200RangeMode::kMm ? 1 : 0;
  setup_mode_ = false;
  output_ = lms200::kModeOnRequest;
  power_on_s_ = NowS();
  reader_.Clear();
  crc_errors_seen_ = reader_.stats().crc_errors;
  const std::string text = PowerOnText(config_.type);
  SendTelegram(lms200::kPowerOn, std::vector<std::uint8_t>(text.begin(), text.end()));
}

void Lms200Emulator::OnBytes(const std::uint8_t* bytes, std::size_t size) {
  // At a rate other than the device's, a real LMS sees framing errors only.
  if (!DriverBaudMatches()) {
    CountRequest(false);
    return;
  }
  const double now = NowS();
  if (reader_.buffered() > 0 && now - last_byte_s_ > kCharacterTimeout_s) reader_.Clear();
  last_byte_s_ = now;
  reader_.Feed(bytes, size);
  for (;;) {
    std::optional<lms200::ReaderEvent> event = reader_.Next();
    // A framed request whose CRC is wrong is NAKed, whether or not anything follows it.
    if (reader_.stats().crc_errors != crc_errors_seen_) {
      crc_errors_seen_ = reader_.stats().crc_errors;
      CountRequest(false);
      Send({lms200::kNak});
    }
    if (!event) break;
    if (event->kind != lms200::ReaderEvent::Kind::kTelegram) continue;
    CountRequest(true);
    Handle(event->telegram);
  }
}

void Lms200Emulator::SendTelegram(std::uint8_t reply_command, std::vector<std::uint8_t> data) {
  data.push_back(kStatusOk);
  Send(lms200::Encode(Telegram{lms200::kReplyAddress, reply_command, std::move(data)}));
}

void Lms200Emulator::Reply(std::uint8_t command, std::vector<std::uint8_t> data) {
  SendTelegram(std::uint8_t(command | lms200::kReplyBit), std::move(data));
}

void Lms200Emulator::SwitchMode(const std::vector<std::uint8_t>& d) {
  const std::uint8_t mode = d[0];
  if (mode == lms200::kModeSetup) {
    setup_mode_ = std::string(d.begin() + 1, d.end()) == "SICK_LMS";
    Reply(lms200::kSwitchMode, {std::uint8_t(setup_mode_ ? 0x00 : 0x01)});
    return;
  }
  for (int baud : {9600, 19200, 38400, 500000}) {
    if (lms200::BaudModeCode(baud) == mode && d.size() == 1) {
      Reply(lms200::kSwitchMode, {0x00});  // acknowledged at the old rate ...
      set_baud(baud);                      // ... then the device switches
      return;
    }
  }
  const int readings = sensors::Lms200Model(current()).readings();
  bool possible = false;
  switch (mode) {
    case lms200::kModeContinuous:
    case lms200::kModeOnRequest:
      possible = d.size() == 1;
      break;
    case lms200::kModeMeanValues:
      // n from 2 to 250 scans (the range sicktoolbox's SetSickOpModeMonitorStreamMeanValues
      // enforces; one byte on the wire).
      possible = d.size() == 2 && d[1] >= 2 && d[1] <= 250;
      if (possible) mean_samples_ = d[1];
      break;
    case lms200::kModeSubrange: {
      // First and last value, counted from 1, inside the current variant's readings.
      const int first = d.size() == 5 ? d[1] | (d[2] << 8) : 0;
      const int last = d.size() == 5 ? d[3] | (d[4] << 8) : 0;
      possible = first >= 1 && first <= last && last <= readings;
      if (possible) subrange_first_ = first, subrange_last_ = last;
      break;
    }
    default:
      break;  // partial scans, mean sub-ranges, field / reflectivity outputs: not emulated
  }
  if (!possible) {
    Reply(lms200::kSwitchMode, {0x02});  // not possible; the mode in force stays
    return;
  }
  setup_mode_ = false;
  output_ = mode;
  next_stream_s_ = NowS();
  Reply(lms200::kSwitchMode, {0x00});
}

void Lms200Emulator::Configure(const std::vector<std::uint8_t>& d) {
  // A shorter block sets its prefix of the full one; the rest stays in force.
  std::vector<std::uint8_t> wanted = config_block_;
  std::copy(d.begin(), d.end(), wanted.begin());
  // Refused (0x00, the block in force echoed) outside installation mode and for what the
  // emulator cannot produce: units other than cm / mm; measuring modes beyond the 8 m / 80 m
  // ones (their values carry reflectivity in bits the decoders read as range); the
  // highest-availability bit and unknown block C bits. Real-time indices are emulated; "dazzle
  // no effect" acts on the switching outputs only, which the emulator does not have.
  const std::uint8_t availability = wanted[lms200::kConfigAvailabilityIndex];
  const bool possible =
      wanted[lms200::kConfigUnitsIndex] <= 1 && wanted[lms200::kConfigMeasuringModeIndex] <= 2 &&
      (availability &
       ~(lms200::kAvailabilityRealTimeIndices | lms200::kAvailabilityDazzleNoEffect)) == 0;
  const bool accepted = setup_mode_ && possible;
  if (accepted) {
    config_block_ = wanted;
    std::lock_guard<std::mutex> lock(mutex_);
    current_.range_mode = wanted[lms200::kConfigUnitsIndex] == 1 ? sensors::Lms200RangeMode::kMm
                                                                 : sensors::Lms200RangeMode::kCm;
  }
  std::vector<std::uint8_t> data = {std::uint8_t(accepted ? 0x01 : 0x00)};
  data.insert(data.end(), config_block_.begin(), config_block_.end());
  Reply(lms200::kConfigure, data);
}

void Lms200Emulator::Handle(const Telegram& request) {
  const auto& d = request.data;
  switch (request.command) {
    case lms200::kSwitchMode:
      if (d.empty()) break;
      Send({lms200::kAck});
      SwitchMode(d);
      return;
    case lms200::kRequestValues:
      if (d.size() != 1 || d[0] != 0x01) break;
      Send({lms200::kAck});
      SendScan(true);
      return;
    case lms200::kRequestType:
      Send({lms200::kAck});
      Reply(lms200::kRequestType,
            std::vector<std::uint8_t>(config_.type.begin(), config_.type.end()));
      return;
    case lms200::kRequestStatus:
      Send({lms200::kAck});
      Reply(lms200::kRequestStatus, StatusBlock());
      return;
    case lms200::kRequestErrors:
      // No errors: only the status byte. sicktoolbox probes the baud rate with this request.
      Send({lms200::kAck});
      Reply(lms200::kRequestErrors, {});
      return;
    case lms200::kSwitchVariant: {
      if (d.size() != 4) break;
      Send({lms200::kAck});
      sensors::Lms200Config wanted = current();
      wanted.fov_deg = d[0] | (d[1] << 8);
      wanted.resolution_deg = (d[2] | (d[3] << 8)) / 100.0;
      bool accepted = true;
      try {
        wanted.Validate();
      } catch (const std::invalid_argument&) {
        accepted = false;
      }
      if (accepted) {
        std::lock_guard<std::mutex> lock(mutex_);
        current_ = wanted;
      }
      std::vector<std::uint8_t> data = {std::uint8_t(accepted ? 0x01 : 0x00)};
      data.insert(data.end(), d.begin(), d.end());
      Reply(lms200::kSwitchVariant, data);
      return;
    }
    case lms200::kRequestConfig:
      Send({lms200::kAck});
      Reply(lms200::kRequestConfig, config_block_);
      return;
    case lms200::kConfigure:
      // The LMS2xx family's block lengths; any other is not a configuration: not acknowledged.
      if (d.size() != lms200::kConfigBlockBytes && d.size() != lms200::kConfigShortBlockBytes)
        break;
      Send({lms200::kAck});
      Configure(d);
      return;
    case lms200::kReset:
      // The reset acknowledgement 0x91, then the device restarts: 9600 baud, the power-on
      // telegram 0x90 when it is ready (sicktoolbox waits for both).
      Send({lms200::kAck});
      SendTelegram(lms200::kResetAck, {});
      OnPowerOn();
      return;
    default:
      break;
  }
  Send({lms200::kNak});  // unknown command or malformed data
}

std::vector<std::uint8_t> Lms200Emulator::StatusBlock() const {
  // The fields the clients read (docs/hardware_interop.md); the pollution, calibration and
  // signal values an LMS also reports are left at zero.
  std::vector<std::uint8_t> b(lms200::kStatusBlockBytes, 0);
  const std::string version = kVersion;
  std::copy(version.begin(), version.end(), b.begin() + lms200::kStatusVersionIndex);
  b[lms200::kStatusOperatingModeIndex] =
      setup_mode_ ? std::uint8_t(lms200::kModeSetup) : output_.load();
  b[lms200::kStatusDeviceStatusIndex] = 0;
  b[lms200::kStatusMeasuringModeIndex] = config_block_[lms200::kConfigMeasuringModeIndex];
  const sensors::Lms200Config now = current();
  const int fov = int(std::lround(now.fov_deg));
  const int res = int(std::lround(now.resolution_deg * 100.0));
  b[lms200::kStatusScanAngleIndex] = std::uint8_t(fov & 0xFF);
  b[lms200::kStatusScanAngleIndex + 1] = std::uint8_t(fov >> 8);
  b[lms200::kStatusResolutionIndex] = std::uint8_t(res & 0xFF);
  b[lms200::kStatusResolutionIndex + 1] = std::uint8_t(res >> 8);
  b[lms200::kStatusUnitsIndex] = now.range_mode == sensors::Lms200RangeMode::kMm ? 1 : 0;
  return b;
}

sensors::LaserLine Lms200Emulator::FlatWall(const sensors::Lms200Config& config) const {
  sensors::Lms200Config quiet = config;
  quiet.noise_sigma_m = 0.0;
  sensors::Lms200Model model(quiet);
  std::vector<float> ranges(std::size_t(model.readings()));
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    const double c = std::cos(model.angle_min_rad() + double(i) * model.angle_increment_rad());
    ranges[i] = c > 0.05 ? float(config_.flat_wall_m / c) : std::numeric_limits<float>::infinity();
  }
  sensors::LaserLine line;
  model.Measure(ranges.data(), nullptr, nullptr, line);
  return line;
}

lms200::MeasuredValues Lms200Emulator::Measure(int samples) {
  // `samples` lines; a reading valid in all of them is their mean, any other the last code.
  const sensors::Lms200Config config = current();
  const std::size_t n = std::size_t(sensors::Lms200Model(config).readings());
  lms200::MeasuredValues mv;
  mv.units =
      config.range_mode == sensors::Lms200RangeMode::kMm ? lms200::Units::kMm : lms200::Units::kCm;
  std::vector<double> sum(n, 0.0);
  std::vector<std::uint16_t> last(n, lms200::kCodeNoReturn);
  std::vector<bool> valid(n, true);
  for (int s = 0; s < samples; ++s) {
    const sensors::LaserLine line = source_ ? source_(config) : FlatWall(config);
    const bool sized = line.ranges_m.size() == n && line.status.size() == n;
    for (std::size_t i = 0; i < n; ++i) {
      last[i] = sized ? lms200::EncodeReading(line.ranges_m[i], line.status[i], mv.units)
                      : lms200::kCodeNoReturn;
      valid[i] = valid[i] && last[i] < lms200::kFirstSpecialCode;
      sum[i] += last[i];
    }
  }
  mv.values.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    mv.values[i] = valid[i] ? std::uint16_t(std::lround(sum[i] / samples)) : last[i];
  }
  if (config_block_[lms200::kConfigAvailabilityIndex] & lms200::kAvailabilityRealTimeIndices) {
    // The mirror turns at 75 Hz from power-on; the index counts its revolutions mod 256.
    mv.real_time_index = std::uint8_t(std::int64_t((NowS() - power_on_s_) * 75.0) & 0xFF);
  }
  return mv;
}

double Lms200Emulator::ScanPeriodS() const {
  // All interlaced sweeps of one line at the mirror's 75 Hz (LMS200 data sheet).
  return sensors::Lms200Model(current()).interlaced_sweeps() / 75.0;
}

void Lms200Emulator::SendScan(bool mirror_wait, double ready_s) {
  // A requested scan waits for the mirror; a streamed one is the newest already measured, ready
  // at `ready_s` (steady clock [s]): its bytes leave from then, or when the line is free.
  if (mirror_wait) std::this_thread::sleep_for(std::chrono::duration<double>(ScanPeriodS()));
  std::optional<std::chrono::steady_clock::time_point> ready;
  if (!mirror_wait) {
    ready = std::chrono::steady_clock::time_point(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(ready_s)));
  }
  const std::uint8_t mode = output_;
  const int samples = mirror_wait || mode != lms200::kModeMeanValues ? 1 : mean_samples_;
  lms200::MeasuredValues mv = Measure(samples);
  if (!mirror_wait && mode == lms200::kModeMeanValues) {
    Send(lms200::Encode(lms200::EncodeMeanValues(samples, mv)), ready);
  } else if (!mirror_wait && mode == lms200::kModeSubrange) {
    const int last = std::min<int>(subrange_last_, int(mv.values.size()));
    const int first = std::min(subrange_first_, last);
    mv.values =
        std::vector<std::uint16_t>(mv.values.begin() + (first - 1), mv.values.begin() + last);
    Send(lms200::Encode(lms200::EncodeSubrangeValues(first, last, mv)), ready);
  } else {
    Send(lms200::Encode(lms200::EncodeMeasuredValues(mv)), ready);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++scans_sent_;
}

void Lms200Emulator::OnIdle() {
  if (!streaming() || !plugged() || NowS() < next_stream_s_) return;
  // The next telegram is due when the mirror has measured it (n lines for a mean); on a slow
  // line it follows the previous telegram directly, as the device sends its newest scan.
  // Due times follow each other by the mirror's period; after a stall (due far behind) the
  // schedule restarts from now rather than catching up.
  const int samples = output_ == lms200::kModeMeanValues ? mean_samples_ : 1;
  const double due_s = next_stream_s_;
  next_stream_s_ = std::max(due_s + samples * ScanPeriodS(), NowS() - ScanPeriodS());
  SendScan(false, due_s);
}

}  // namespace pitchlab::hw
