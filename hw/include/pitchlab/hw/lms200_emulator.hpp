#pragma once
// An emulated SICK LMS200 on a pseudo-terminal: ACK then reply at the line rate; power-on
// telegram; reset; baud switch acknowledged at the old rate; variant, range mode, configuration
// blocks of 32 or 34 bytes, real-time scan indices, single scans and the streamed outputs (all
// values, mean of n scans, a sub-range). What is refused and why: docs/hardware_interop.md.
// Ranges come from a callback (the simulator, or a built-in flat wall).

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

#include "pitchlab/hw/emulated_device.hpp"
#include "pitchlab/hw/lms200_protocol.hpp"
#include "pitchlab/sensors/laser_line.hpp"
#include "pitchlab/sensors/lms200.hpp"

namespace pitchlab::hw {

/// How the emulated LMS200 starts.
struct Lms200EmulatorConfig {
  int power_on_baud = 9600;           ///< rate after power-on [bit/s]
  sensors::Lms200Config lms;          ///< initial variant and range mode (baud ignored)
  std::string type = "LMS200;30106";  ///< answer to the type request
  double flat_wall_m = 3.0;           ///< built-in source: wall this far ahead [m]
};

/// The readings of one line for the device's current variant and range mode; ranges and status
/// as sensors::Lms200Model::Measure fills them. A line of the wrong size is sent as "no return".
using LineSourceFn = std::function<sensors::LaserLine(const sensors::Lms200Config&)>;

/// The device. Construct, hand path() to a driver; destroy to unplug for good.
class Lms200Emulator final : public EmulatedDevice {
 public:
  /// `source` empty: a flat wall `flat_wall_m` ahead. Throws like EmulatedDevice.
  explicit Lms200Emulator(const Lms200EmulatorConfig& config, LineSourceFn source = {},
                          std::string link_path = "");
  ~Lms200Emulator() override;
  /// The variant and range mode the device is in now.
  sensors::Lms200Config current() const;
  /// Measured-value telegrams sent so far.
  std::size_t scans_sent() const;
  /// True while the device streams measured values (modes 0x24, 0x26, 0x27).
  bool streaming() const { return output_ != lms200::kModeOnRequest; }

 private:
  void OnBytes(const std::uint8_t* bytes, std::size_t size) override;
  void OnIdle() override;
  void OnPowerOn() override;
  void Handle(const lms200::Telegram& request);
  void SwitchMode(const std::vector<std::uint8_t>& d);
  void Configure(const std::vector<std::uint8_t>& d);
  void Reply(std::uint8_t command, std::vector<std::uint8_t> data);
  void SendTelegram(std::uint8_t reply_command, std::vector<std::uint8_t> data);
  lms200::MeasuredValues Measure(int samples);
  void SendScan(bool mirror_wait, double ready_s = 0.0);
  double ScanPeriodS() const;
  std::vector<std::uint8_t> StatusBlock() const;
  sensors::LaserLine FlatWall(const sensors::Lms200Config& config) const;

  Lms200EmulatorConfig config_;
  LineSourceFn source_;
  lms200::TelegramReader reader_{0x00};
  std::size_t crc_errors_seen_ = 0;
  double last_byte_s_ = 0.0;  // when the last request byte came (the character timeout)
  mutable std::mutex mutex_;  // guards current_, scans_sent_
  sensors::Lms200Config current_;
  std::size_t scans_sent_ = 0;
  bool setup_mode_ = false;
  std::atomic<std::uint8_t> output_{lms200::kModeOnRequest};  // 0x24 / 0x25 / 0x26 / 0x27
  int mean_samples_ = 1;                                      // mode 0x26: n
  int subrange_first_ = 1, subrange_last_ = 1;                // mode 0x27 [index from 1]
  double next_stream_s_ = 0.0;
  double power_on_s_ = 0.0;  // the mirror's revolutions count from here
  std::vector<std::uint8_t> config_block_;
};

}  // namespace pitchlab::hw
