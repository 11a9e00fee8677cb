#pragma once
// The pitch-unit driver behind the PitchAxis seam (docs/pitch_unit_protocol.md).

#include <chrono>
#include <memory>
#include <string>

#include "pitchlab/hw/pitch_unit_protocol.hpp"
#include "pitchlab/hw/serial_port.hpp"
#include "pitchlab/sensors/pitch_unit.hpp"
#include "pitchlab/sensors/scan_source.hpp"

namespace pitchlab::hw {

struct PitchUnitDriverConfig {
  std::string device;             ///< serial device
  int baud = 38400;               ///< [bit/s]
  sensors::PitchUnitConfig unit;  ///< must agree with what the board reports
  int reply_timeout_ms = 200;     ///< per request [ms]
  int retries = 3;                ///< attempts per request
  int poll_period_ms = 10;        ///< STATUS polling while moving [ms]

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// PitchAxis over the serial board.
class PitchUnitDriver final : public sensors::PitchAxis {
 public:
  /// Opens the port and PINGs the board. Throws std::runtime_error naming the device when it
  /// does not answer or reports a step size / encoder resolution other than the config's.
  explicit PitchUnitDriver(const PitchUnitDriverConfig& config);
  /// MOVE to the nearest step, poll STATUS until settled at it, return the encoder angle [rad].
  [[nodiscard]] Result<double> MoveTo(double pitch_rad, std::chrono::milliseconds timeout) override;
  [[nodiscard]] Result<double> ReadEncoder() override;
  const pitch::Info& info() const { return info_; }
  std::size_t retries() const { return retries_; }

 private:
  Result<pitch::Frame> Request(const pitch::Frame& request);
  double Angle(std::int32_t count) const;

  PitchUnitDriverConfig config_;
  sensors::PitchUnitModel model_;
  std::unique_ptr<SerialPort> port_;
  pitch::FrameReader reader_;
  pitch::Info info_;
  std::size_t retries_ = 0;
};

}  // namespace pitchlab::hw
