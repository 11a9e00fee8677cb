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
  setup_mode_ = streaming_ = false;
  reader_.Clear();
  crc_errors_seen_ = reader_.stats().crc_errors;
  const std::string text = PowerOnText(config_.type);
  Reply(lms200::kPowerOn, std::vector<std::uint8_t>(text.begin(), text.end()));
}

void Lms200Emulator::OnBytes(const std::uint8_t* bytes, std::size_t size) {
  // At a rate other than the device's, a real LMS sees framing errors only.
  if (!DriverBaudMatches()) {
    CountRequest(false);
    return;
  }
  reader_.Feed(bytes, size);
  while (auto event = reader_.Next()) {
    if (reader_.stats().crc_errors != crc_errors_seen_) {
      crc_errors_seen_ = reader_.stats().crc_errors;
      CountRequest(false);
      Send({lms200::kNak});
    }
    if (event->kind != lms200::ReaderEvent::Kind::kTelegram) continue;
    CountRequest(true);
    Handle(event->telegram);
  }
}

void Lms200Emulator::Reply(std::uint8_t command, std::vector<std::uint8_t> data) {
  data.push_back(kStatusOk);
  Send(lms200::Encode(
      Telegram{lms200::kReplyAddress, std::uint8_t(command | lms200::kReplyBit), std::move(data)}));
}

void Lms200Emulator::Handle(const Telegram& request) {
  const auto& d = request.data;
  switch (request.command) {
    case lms200::kSwitchMode: {
      if (d.empty()) break;
      Send({lms200::kAck});
      const std::uint8_t mode = d[0];
      if (mode == lms200::kModeSetup) {
        setup_mode_ = std::string(d.begin() + 1, d.end()) == "SICK_LMS";
        Reply(lms200::kSwitchMode, {std::uint8_t(setup_mode_ ? 0x00 : 0x01)});
        return;
      }
      for (int baud : {9600, 19200, 38400, 500000}) {
        if (lms200::BaudModeCode(baud) == mode) {
          Reply(lms200::kSwitchMode, {0x00});  // acknowledged at the old rate ...
          set_baud(baud);                      // ... then the device switches
          return;
        }
      }
      if (mode == lms200::kModeContinuous || mode == lms200::kModeOnRequest) {
        setup_mode_ = false;
        streaming_ = mode == lms200::kModeContinuous;
        next_stream_s_ = NowS();
        Reply(lms200::kSwitchMode, {0x00});
        return;
      }
      Reply(lms200::kSwitchMode, {0x02});
      return;
    }
    case lms200::kRequestValues:
      if (d.size() != 1 || d[0] != 0x01) break;
      Send({lms200::kAck});
      SendScan();
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
    case lms200::kConfigure: {
      // A block of another length is not an LMS200 configuration: not acknowledged.
      if (d.size() != lms200::kConfigBlockBytes) break;
      Send({lms200::kAck});
      // Refused (0x00, block echoed) outside installation mode, and for what this emulator
      // cannot produce: units other than cm / mm, measuring modes beyond the 8 m / 80 m ones
      // (their values carry reflectivity in bits the decoders read as range).
      const bool possible =
          d[lms200::kConfigUnitsIndex] <= 1 && d[lms200::kConfigMeasuringModeIndex] <= 2;
      std::vector<std::uint8_t> data = {std::uint8_t(setup_mode_ && possible ? 0x01 : 0x00)};
      if (setup_mode_ && possible) {
        config_block_ = d;
        std::lock_guard<std::mutex> lock(mutex_);
        current_.range_mode = d[lms200::kConfigUnitsIndex] == 1 ? sensors::Lms200RangeMode::kMm
                                                                : sensors::Lms200RangeMode::kCm;
      }
      data.insert(data.end(), config_block_.begin(), config_block_.end());
      Reply(lms200::kConfigure, data);
      return;
    }
    case lms200::kReset:
      Send({lms200::kAck});
      Reply(lms200::kReset, {});
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
      setup_mode_ ? lms200::kModeSetup
                  : (streaming_ ? lms200::kModeContinuous : lms200::kModeOnRequest);
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

void Lms200Emulator::SendScan() {
  const sensors::Lms200Config config = current();
  const sensors::Lms200Model model(config);
  const sensors::LaserLine line = source_ ? source_(config) : FlatWall(config);
  // The mirror has to turn (all interlaced sweeps) before the reply can start.
  std::this_thread::sleep_for(std::chrono::duration<double>(model.interlaced_sweeps() / 75.0));
  lms200::MeasuredValues mv;
  mv.units =
      config.range_mode == sensors::Lms200RangeMode::kMm ? lms200::Units::kMm : lms200::Units::kCm;
  const std::size_t n = std::size_t(model.readings());
  const bool sized = line.ranges_m.size() == n && line.status.size() == n;
  mv.values.resize(n, lms200::kCodeNoReturn);
  for (std::size_t i = 0; sized && i < n; ++i) {
    mv.values[i] = lms200::EncodeReading(line.ranges_m[i], line.status[i], mv.units);
  }
  Send(lms200::Encode(lms200::EncodeMeasuredValues(mv)));
  std::lock_guard<std::mutex> lock(mutex_);
  ++scans_sent_;
}

void Lms200Emulator::OnIdle() {
  if (!streaming_ || !plugged() || NowS() < next_stream_s_) return;
  const sensors::Lms200Model model(current());
  next_stream_s_ = NowS() + model.interlaced_sweeps() / 75.0;
  SendScan();
}

}  // namespace pitchlab::hw
