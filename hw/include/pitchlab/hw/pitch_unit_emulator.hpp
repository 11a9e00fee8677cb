#pragma once
// An emulated pitch-unit board on a pseudo-terminal (docs/pitch_unit_protocol.md). Motion comes
// from callbacks (the simulated mount), or from a built-in slew-and-settle model.

#include <functional>
#include <mutex>
#include <string>

#include "pitchlab/hw/emulated_device.hpp"
#include "pitchlab/hw/pitch_unit_protocol.hpp"
#include "pitchlab/sensors/pitch_unit.hpp"

namespace pitchlab::hw {

/// The mount's physics as the board sees it.
struct PitchPhysics {
  /// A new setpoint [rad] (the angle of a servo step). May block while the mount moves.
  std::function<void(double target_rad)> command;
  /// True angle [rad] and whether the mount is still moving or settling.
  std::function<std::pair<double, bool>()> state;
};

/// The board. Construct, hand path() to a driver.
class PitchUnitEmulator final : public EmulatedDevice {
 public:
  /// `physics` empty: slews at max_speed_dps and settles for settle_s. Throws on a bad config.
  explicit PitchUnitEmulator(const sensors::PitchUnitConfig& config, int baud = 38400,
                             PitchPhysics physics = {}, std::string link_path = "");
  ~PitchUnitEmulator() override;

 private:
  void OnBytes(const std::uint8_t* bytes, std::size_t size) override;
  void Handle(const pitch::Frame& request);
  std::pair<double, bool> State();
  std::int32_t Count(double angle_rad) const;

  sensors::PitchUnitModel model_;
  PitchPhysics physics_;
  pitch::FrameReader reader_;
  std::size_t crc_errors_seen_ = 0;
  std::int16_t target_step_ = 0;
  bool clamped_ = false;
  // Built-in model: a linear slew from start to target beginning at move_start_s_.
  double start_rad_ = 0.0, target_rad_ = 0.0, move_start_s_ = 0.0;
};

}  // namespace pitchlab::hw
