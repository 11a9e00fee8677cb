#pragma once
// SICK LMS200 measurement model: beam layout, range modes, quantization, flags, noise and timing.

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
  double noise_sigma_m = 0.005;    ///< Gaussian range noise, 0 = off [m]
  double range_bias_m = 0.0;       ///< systematic offset added to every range [m]
  bool mixed_pixels = false;       ///< average foreground and background at depth edges
  double beam_divergence_deg = 0.25;  ///< full beam width used for mixed pixels [deg]
  int baud = 500000;               ///< serial rate: 9600, 19200, 38400 or 500000 [bit/s]
  std::uint64_t seed = 1;          ///< noise seed

  /// Throws std::invalid_argument naming the field and value when the LMS200 has no such mode.
  void Validate() const;
};

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
  /// the two edges of each beam (else ignored, may be null). Stamp and pitch are left to the caller.
  void Measure(const float* true_ranges, const float* edge_lo, const float* edge_hi,
               LaserLine& line);

 private:
  Lms200Config config_;
  int readings_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
};

}  // namespace pitchlab::sensors
