#pragma once
// An emulated SICK LMS200 on a pseudo-terminal: ACK then reply, paced at the baud rate; power-on
// telegram; baud switch acknowledged at the old rate; variant, range mode, single scans and
// continuous output. Ranges come from a callback (the simulator, or a built-in flat wall).

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
  /// True while the device streams measured values (mode 0x24).
  bool streaming() const { return streaming_; }

 private:
  void OnBytes(const std::uint8_t* bytes, std::size_t size) override;
  void OnIdle() override;
  void OnPowerOn() override;
  void Handle(const lms200::Telegram& request);
  void Reply(std::uint8_t command, std::vector<std::uint8_t> data);
  void SendScan();
  std::vector<std::uint8_t> StatusBlock() const;
  sensors::LaserLine FlatWall(const sensors::Lms200Config& config) const;

  Lms200EmulatorConfig config_;
  LineSourceFn source_;
  lms200::TelegramReader reader_{0x00};
  std::size_t crc_errors_seen_ = 0;
  mutable std::mutex mutex_;  // guards current_, scans_sent_
  sensors::Lms200Config current_;
  std::size_t scans_sent_ = 0;
  bool setup_mode_ = false;
  std::atomic<bool> streaming_{false};
  double next_stream_s_ = 0.0;
  std::vector<std::uint8_t> config_block_;
};

}  // namespace pitchlab::hw
