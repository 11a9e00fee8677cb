#pragma once
// The pitching mount's servo and encoder: commanded angle -> servo step -> encoder angle.

namespace pitchlab::sensors {

struct PitchUnitConfig {
  double step_deg = 0.45;          ///< servo's minimum step [deg]
  int encoder_counts_per_rev = 36000;  ///< encoder resolution (36000 = 0.01 deg) [counts]
  double min_deg = -60.0;          ///< mechanical limit, nose up [deg]
  double max_deg = 90.0;           ///< mechanical limit, nose down [deg]
  double max_speed_dps = 90.0;     ///< servo slew rate [deg/s]
  double settle_s = 0.02;          ///< wait after reaching the step before a line [s]

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// Pure quantization model of the pitch unit, shared by the simulator and the driver.
class PitchUnitModel {
 public:
  explicit PitchUnitModel(const PitchUnitConfig& config);  ///< validates; throws

  const PitchUnitConfig& config() const { return config_; }
  /// Servo step nearest `pitch_rad`, clamped to the mechanical limits.
  int StepFor(double pitch_rad) const;
  /// Angle of servo step `step` [rad].
  double StepAngle(int step) const;
  /// What the encoder reads at true angle `pitch_rad` [rad] (quantized to one count).
  double EncoderAngle(double pitch_rad) const;
  /// Time to slew from `from_rad` to `to_rad` and settle [s].
  double MoveTime(double from_rad, double to_rad) const;

 private:
  PitchUnitConfig config_;
};

}  // namespace pitchlab::sensors
