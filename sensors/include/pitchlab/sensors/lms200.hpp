#pragma once
// SICK LMS200 measurement model: beam layout, range modes, quantization, flags, noise and timing.

#include <array>
#include <cstdint>
#include <random>

#include "pitchlab/sensors/laser_line.hpp"

namespace pitchlab::sensors {

/// Range mode: the unit of the 13-bit reading fixes resolution and maximum range.
enum class Lms200RangeMode {
  kCm,  ///< 1 cm unit, max 81.91 m
  kMm,  ///< 1 mm unit, max 8.191 m
};

struct Lms200Config {
  double fov_deg = 180.0;          ///< 100 or 180 [deg]
  double resolution_deg = 0.5;     ///< 1, 0.5 or 0.25 (0.25 only with 100) [deg]
  Lms200RangeMode range_mode = Lms200RangeMode::kCm;
  // Range noise: Gaussian, sigma^2 = noise_sigma_m^2 + (noise_per_m x range)^2
  //   + (incidence_noise_gain x range x beam divergence x tan(min(incidence, max)))^2,
  // max = incidence_noise_max_deg. The last term is the depth the beam's footprint spans on a
  // surface it meets obliquely (a footprint range x divergence wide, tilted by the incidence): the
  // echo's time spreads over it. Measured() rests on three real scans of a pitching SICK LMS2xx
  // in a corridor (3DTK; two shipped, one held out; benchmarks/sensor_realism, tables in
  // benchmarks/README.md):
  //  - noise_sigma_m 2 mm: their local plane-fit residual within 45 deg of head-on at 0-2 m is
  //    3.2 mm (robust sigma), cm-mode quantization alone 2.9 mm; 2 mm gives the sim 3.6 mm.
  //  - noise_per_m 1.5 mm/m: surfaces met within 45 deg of head-on scatter off their two
  //    neighbours of the same interlaced sweep (which share its pitch: no servo error enters) by
  //    3.3 / 4.0 / 8.1 mm at 0-2 / 2-4 / 4-8 m; 1.5 mm/m gives 9 mm of range noise at 6 m (SICK's
  //    LMS200 technical description quotes ~1 cm sigma at 1-20 m in cm mode: 7 m here).
  //  - incidence_noise_gain 0.2 up to incidence_noise_max_deg 75: the same in-sweep scatter of
  //    every surface is 1.9 / 2.9 / 4.9 mm at 0-2 / 2-4 / 4-8 m, and of the floor alone, met at
  //    45-87 deg, 1.7 / 2.0 / 1.8 mm (each sweep's pitch set right): the floor's range noise stops
  //    growing with its incidence. The simulated corridor in the real scans' mm resolution gives
  //    2.0 / 2.7 / 3.0 mm and floor 2.0 / 2.1 / 2.2 mm; the term as it was (gain 0.4, growing to
  //    85 deg) 2.0 / 4.5 / 8.3 and 2.1 / 4.4 / 9.0 mm, 2-5x the real floor. What the real walls
  //    keep at 4-8 m beyond the model's 3.0 mm is taken for their texture (doors, frames): a
  //    sweep's neighbours lie 0.6 m apart along a wall met at 80 deg 6 m away, and the simulated
  //    walls are flat.
  // noise_sigma_m = 0 is the ideal sensor: no range noise of any term and no dropouts (what the
  // tests and the emulator's flat wall rely on).
  //
  // The defaults are Measured()'s. Legacy() is the constant-noise model the first figures were
  // set on (5 mm, no growth, no dropouts, a perfect mount); benchmarks/README.md compares the two.
  double noise_sigma_m = 0.002;    ///< range noise at 0 m and normal incidence [m]
  double noise_per_m = 0.0015;     ///< range noise growth per metre of range (quadrature) [m/m]
  double incidence_noise_gain = 0.2;      ///< footprint-depth noise gain, 0 = off [1]
  double incidence_noise_max_deg = 75.0;  ///< incidence beyond which it grows no more [deg]
  double range_bias_m = 0.0;       ///< systematic offset added to every range [m]
  /// Average foreground and background at depth edges. Off: the real scans show 0.11 single
  /// returns between two surfaces per depth edge, the simulated cluttered world 0.16 without
  /// any blending (geometry and noise) and 0.31 with it; the data show no blending to add.
  bool mixed_pixels = false;
  double beam_divergence_deg = 0.25;  ///< full beam width: mixed pixels, footprint depth [deg]
  // Dropouts: a return is lost with probability p = grazing + far (capped at 1), each a ramp:
  //   grazing = dropout_grazing_at_90 x (incidence - start) / (90 deg - start),
  //             start = dropout_grazing_deg
  //   far     = dropout_far_per_m x (range - dropout_far_m)          (each 0 below its onset)
  // The real scans' no-returns among agreeing returns (located dropouts) are 0.02 / 0.13 / 0.54 /
  // 0.81 % of the returns at 0-2 / 2-4 / 4-8 / 8-16 m: 0.1 % per metre beyond 2 m. By incidence
  // they are 0.16 / 0.11 / 0.10 / 0.23 % at 0-30 / 30-60 / 60-75 / 75+ deg, and the range ramp
  // alone gives the simulated corridor 0.23 % at 75+ deg (grazing surfaces are far ones there):
  // no grazing dropouts beyond range's, so the grazing ramp is off by default.
  double dropout_grazing_deg = 75.0;  ///< incidence where grazing dropouts begin [deg]
  double dropout_grazing_at_90 = 0.0;  ///< dropout probability at 90 deg incidence, 0 = off [1]
  double dropout_far_m = 2.0;      ///< range where long-range dropouts begin [m]
  double dropout_far_per_m = 0.001;  ///< dropout probability added per metre beyond it [1/m]
  // The true scanner pose on the robot differs from the nominal MountConfig by a rotation drawn
  // once per run (roll, pitch, yaw each N(0, sigma), added to the nominal misalignment): the
  // simulator scans with it, the pipeline assembles with the nominal mount and never learns it
  // (sim::SimRig). The real scanner, never calibrated, sits 3.0 and 4.3 deg off the floor in its
  // two scans (sigma 3 deg reproduces that). A pitchlab robot is calibrated by a floor fit
  // (mapping::CalibrateMountFromFloor): good to ~0.01 deg over thousands of floor points, so what
  // remains is the calibration floor's own slope under the robot, which we assume flat to ~4 mm
  // over the ~1 m the robot spans (a finished indoor floor): 0.25 deg, yaw alike. A mission
  // calibrates again on its start pad (MissionConfig::calibrate_mount), which the worlds keep
  // flat: the error drawn here is what a run without that sees.
  double mount_error_sigma_deg = 0.25;  ///< per-axis sigma of the drawn rotation, 0 = off [deg]
  int baud = 500000;               ///< serial rate: 9600, 19200, 38400 or 500000 [bit/s]
  std::uint64_t seed = 1;          ///< noise seed (also draws the dropouts and the mount error)

  /// Throws std::invalid_argument naming the field and value when the LMS200 has no such mode.
  void Validate() const;
  /// The model before issue 16: constant 5 mm noise, no mixed pixels, no dropouts, a perfect
  /// mount.
  static Lms200Config Legacy();
  /// The model measured on real scans (the comments above), the default: noise 2 mm + 1.5 mm/m
  /// + footprint depth x 0.2 (up to 75 deg of incidence), dropouts 0.1 % per metre beyond 2 m, a
  /// 0.25 deg mount error drawn per run.
  static Lms200Config Measured();
  /// True when Measure needs the incidence of each beam (incidence noise or grazing dropouts).
  bool UsesIncidence() const { return incidence_noise_gain > 0.0 || dropout_grazing_at_90 > 0.0; }
};

/// The mount rotation error of a run: roll, pitch, yaw [rad], each N(0, mount_error_sigma_deg),
/// drawn from `config.seed` on a stream of its own (all zero when the sigma is 0).
std::array<double, 3> DrawMountErrorRpyRad(const Lms200Config& config);

/// The angle between an LMS200's beams within one turn of its mirror: 1 deg [rad]. Its finer
/// resolutions interlace turns (LMS200 manual: at 0.5 deg two 1 deg sweeps offset by 0.5 deg, at
/// 0.25 deg four; one turn 13.3 ms), so a nodding unit that moves during a line gives each sweep
/// a pitch of its own.
inline constexpr double kLms200TurnRad = 0.0174532925199432957;

/// How many interlaced sweeps a line of beams `beam_step_rad` apart is made of: turn / step when
/// that is a whole number of at least 2 (within a tenth of a beam), else 1 (also for a step <= 0).
/// Reading i of a line (counted from a beam a whole number of turns from straight ahead, as the
/// LMS200's -90 deg first beam is) is in sweep i mod that.
int InterlacedSweeps(double beam_step_rad, double turn_rad = kLms200TurnRad);

/// Turns true ranges into LMS200 readings. Deterministic for a given seed and call sequence.
class Lms200Model {
 public:
  explicit Lms200Model(const Lms200Config& config);  ///< validates; throws std::invalid_argument

  const Lms200Config& config() const { return config_; }
  int readings() const { return readings_; }               ///< readings per line (361 for 180/0.5)
  double angle_min_rad() const;                            ///< first beam angle [rad] (-fov/2)
  double angle_increment_rad() const;                      ///< [rad]
  double unit_m() const;                                   ///< reading unit: 0.01 or 0.001 [m]
  double max_range_m() const;                              ///< 81.91 or 8.191 [m]
  int interlaced_sweeps() const;                           ///< mirror turns per line: 1, 2 or 4
  double measurement_time_s() const;                       ///< mirror time for one line [s]
  int telegram_bytes() const;                              ///< bytes of one measured-value reply
  double transfer_time_s() const;                          ///< telegram bytes at the baud rate [s]
  double line_period_s() const;                            ///< measurement + transfer [s]

  /// Fills `line` (ranges, status, angles, duration) from true ranges along each beam [m],
  /// +inf where nothing was hit. With mixed pixels on, `edge_lo`/`edge_hi` are the true ranges at
  /// the two edges of each beam (else ignored, may be null). `cos_incidence` is each beam's
  /// |cos| of the angle to the surface normal where it hit (null: normal incidence, no incidence
  /// effects). Stamp and pitch are left to the caller.
  void Measure(const float* true_ranges, const float* edge_lo, const float* edge_hi,
               LaserLine& line, const float* cos_incidence = nullptr);
  /// The range noise sigma at `range_m` and incidence `incidence_rad` (the formula above) [m].
  double NoiseSigma(double range_m, double incidence_rad) const;
  /// The dropout probability at `range_m` and incidence `incidence_rad` (the formula above).
  double DropoutProbability(double range_m, double incidence_rad) const;

 private:
  Lms200Config config_;
  int readings_ = 0;
  std::mt19937_64 rng_;      // range noise: the same draws whatever the other effects
  std::mt19937_64 effects_;  // dropouts, on a stream of their own
  std::normal_distribution<double> noise_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

}  // namespace pitchlab::sensors
