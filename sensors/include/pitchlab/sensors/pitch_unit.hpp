#pragma once
// The pitching mount's servo and encoder: commanded angle -> servo step -> encoder angle.

#include <cstdint>

namespace pitchlab::sensors {

struct PitchUnitConfig {
  double step_deg = 0.45;              ///< servo's minimum step [deg]
  int encoder_counts_per_rev = 36000;  ///< encoder resolution (36000 = 0.01 deg) [counts]
  double min_deg = -60.0;              ///< mechanical limit, nose up [deg]
  double max_deg = 90.0;               ///< mechanical limit, nose down [deg]
  double max_speed_dps = 90.0;         ///< servo slew rate [deg/s]
  double settle_s = 0.02;              ///< wait after reaching the step before a line [s]
  // The pitch a simulated unit reports for a line is off the laser's true pitch by an error that
  // depends on the pitch only (the same at the same pitch in every scan of a run): a wobble of
  // period line_pitch_error_period_deg plus steps that change every period (a gear's tooth, a
  // coupling's play), each half the variance, RMS line_pitch_error_deg. The real 3DTK rig's
  // lines are off their floor by 0.9 / 1.0 deg RMS (two scans), a wobble of ~8 lines (4.2 deg at
  // its 0.52 deg lines) with jumps of 2-3 deg between neighbouring lines, at about the same
  // pitches in both scans (mapping/README.md, "Line pitch"; line for line the two correlate only
  // 0.6: the real jumps move by a few degrees from scan to scan, these do not); steps of RMS 0.9 deg / sqrt(2) give jumps of
  // RMS 0.9 deg, 2.7 deg at 3 sigma. 0 (the default) is a unit that reports its true pitch, as
  // every simulated figure so far assumed.
  double line_pitch_error_deg = 0.0;         ///< RMS of the reported pitch's error [deg]
  double line_pitch_error_period_deg = 4.2;  ///< period of the wobble, width of a step [deg]
  // An LMS200 line finer than 1 deg is several turns of its mirror interlaced (at 0.5 deg two 1
  // deg sweeps, one turn, 13.3 ms, apart; LMS200 manual). A unit that pitches on during a line
  // takes each sweep this much further down than the one before: the real 3DTK rig's two sweeps
  // lie 0.16 deg apart on average (mapping/README.md, Line pitch). The simulated line casts sweep
  // k at its pitch + k x this, about the laser's own origin (0.09 m above the axis: 0.3 mm off
  // at 0.2 deg). 0 (the default): a unit that holds its step through the line.
  double sweep_lag_deg = 0.0;  ///< pitch between consecutive interlaced sweeps of a line [deg]
  std::uint64_t seed = 1;                    ///< draws the error's phase and steps

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
  /// The error of the reported pitch at true pitch `pitch_rad` (config's line_pitch_error_*;
  /// 0 when off) [rad]. Deterministic for a given seed.
  double LinePitchError(double pitch_rad) const;
  /// What the unit reports at true angle `pitch_rad`: the encoder's reading of the angle off by
  /// LinePitchError [rad].
  double ReportedAngle(double pitch_rad) const;
  /// Time to slew from `from_rad` to `to_rad` and settle [s].
  double MoveTime(double from_rad, double to_rad) const;

 private:
  PitchUnitConfig config_;
  double phase_rad_ = 0.0;   // the wobble's phase
  double offset_rad_ = 0.0;  // where the first step starts, within one period
};

}  // namespace pitchlab::sensors
