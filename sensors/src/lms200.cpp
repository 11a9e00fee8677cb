#include "pitchlab/sensors/lms200.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pitchlab::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
// The LMS200's mirror turns at 75 Hz; finer resolutions interlace several turns per line.
constexpr double kMirrorRate_hz = 75.0;
// A reading is 13 bits of range: 8191 units is the largest value (and the no-return code).
constexpr double kMaxCountsInRange = 8191.0;
// A measured-value reply: STX, address, length (2), command, count (2), 2 bytes a reading,
// status, CRC (2). 8N1 framing puts 10 bits on the wire per byte.
constexpr int kTelegramOverheadBytes = 10;
constexpr int kBitsPerByte = 8 + 2;
// Depth jump across one beam's footprint above which the return is a mixed pixel [m].
constexpr double kMixedPixelJump_m = 0.05;
// Largest range noise a config may ask for [m] (see Lms200Config::Validate).
constexpr double kMaxNoiseSigma_m = 1.0;

// Seeds of the dropout and the mount streams: the run's seed with fixed bits flipped, so the range
// noise keeps its draws whichever effects are on (any constants do; these are the first digits of
// pi and e in hexadecimal).
constexpr std::uint64_t kEffectsStream = 0x243F6A8885A308D3ULL;
constexpr std::uint64_t kMountStream = 0xB7E151628AED2A6BULL;

bool Near(double a, double b) { return std::abs(a - b) < 1e-9; }

[[noreturn]] void Invalid(const char* field, double value, const char* allowed) {
  std::ostringstream os;
  os << "lms200." << field << " = " << value << " is not an LMS200 setting (allowed: " << allowed
     << ")";
  throw std::invalid_argument(os.str());
}

}  // namespace

void Lms200Config::Validate() const {
  if (!Near(fov_deg, 100.0) && !Near(fov_deg, 180.0)) Invalid("fov_deg", fov_deg, "100, 180");
  if (!Near(resolution_deg, 1.0) && !Near(resolution_deg, 0.5) && !Near(resolution_deg, 0.25)) {
    Invalid("resolution_deg", resolution_deg, "1, 0.5, 0.25");
  }
  if (Near(resolution_deg, 0.25) && !Near(fov_deg, 100.0)) {
    Invalid("resolution_deg", resolution_deg, "0.25 only with fov_deg 100");
  }
  // A guard against a unit slip: 1 m is 200 times the datasheet's 5 mm and an eighth of mm mode's
  // range; a wall 4 m away would read anywhere from 1 to 7 m, no longer a range finder.
  if (!(noise_sigma_m >= 0.0 && noise_sigma_m <= kMaxNoiseSigma_m)) {
    Invalid("noise_sigma_m", noise_sigma_m, "0 .. 1 [m] (the datasheet's is 0.005)");
  }
  if (!(noise_per_m >= 0.0 && noise_per_m < 0.1)) Invalid("noise_per_m", noise_per_m, "0 .. 0.1");
  if (!(incidence_noise_gain >= 0.0 && incidence_noise_gain <= 10.0)) {
    Invalid("incidence_noise_gain", incidence_noise_gain, "0 .. 10");
  }
  // tan() grows without bound towards 90 deg: 89 deg (tan 57) is as far as a footprint goes.
  if (!(incidence_noise_max_deg >= 0.0 && incidence_noise_max_deg <= 89.0)) {
    Invalid("incidence_noise_max_deg", incidence_noise_max_deg, "0 .. 89");
  }
  if (!std::isfinite(range_bias_m)) Invalid("range_bias_m", range_bias_m, "a finite number");
  if (!(dropout_grazing_deg >= 0.0 && dropout_grazing_deg < 90.0)) {
    Invalid("dropout_grazing_deg", dropout_grazing_deg, "0 .. < 90");
  }
  if (!(dropout_grazing_at_90 >= 0.0 && dropout_grazing_at_90 <= 1.0)) {
    Invalid("dropout_grazing_at_90", dropout_grazing_at_90, "0 .. 1");
  }
  if (!(dropout_far_m >= 0.0) || !std::isfinite(dropout_far_m)) {
    Invalid("dropout_far_m", dropout_far_m, ">= 0");
  }
  if (!(dropout_far_per_m >= 0.0 && dropout_far_per_m <= 1.0)) {
    Invalid("dropout_far_per_m", dropout_far_per_m, "0 .. 1");
  }
  // A mount more than 10 deg off is a mounting fault, not a calibration residual.
  if (!(mount_error_sigma_deg >= 0.0 && mount_error_sigma_deg <= 10.0)) {
    Invalid("mount_error_sigma_deg", mount_error_sigma_deg, "0 .. 10");
  }
  if (!(beam_divergence_deg >= 0.0 && beam_divergence_deg < 5.0)) {
    Invalid("beam_divergence_deg", beam_divergence_deg, "0 .. 5");
  }
  if (baud != 9600 && baud != 19200 && baud != 38400 && baud != 500000) {
    Invalid("baud", baud, "9600, 19200, 38400, 500000");
  }
}

Lms200Config Lms200Config::Legacy() {
  Lms200Config c;
  c.noise_sigma_m = 0.005;
  c.noise_per_m = 0.0;
  c.incidence_noise_gain = 0.0;
  c.mixed_pixels = false;
  c.dropout_grazing_at_90 = 0.0;
  c.dropout_far_per_m = 0.0;
  c.mount_error_sigma_deg = 0.0;
  return c;
}

Lms200Config Lms200Config::Measured() { return Lms200Config{}; }

std::array<double, 3> DrawMountErrorRpyRad(const Lms200Config& config) {
  std::array<double, 3> rpy = {0.0, 0.0, 0.0};
  if (config.mount_error_sigma_deg <= 0.0) return rpy;
  std::mt19937_64 rng(config.seed ^ kMountStream);
  std::normal_distribution<double> normal(0.0, config.mount_error_sigma_deg * kDegToRad);
  for (double& a : rpy) a = normal(rng);
  return rpy;
}

int InterlacedSweeps(double beam_step_rad, double turn_rad) {
  if (!(beam_step_rad > 0.0)) return 1;
  const double ratio = turn_rad / beam_step_rad;
  const long n = std::lround(ratio);
  return n >= 2 && std::abs(ratio - static_cast<double>(n)) < 0.1 ? static_cast<int>(n) : 1;
}

Lms200Model::Lms200Model(const Lms200Config& config)
    : config_(config), rng_(config.seed), effects_(config.seed ^ kEffectsStream) {
  config_.Validate();
  readings_ = static_cast<int>(std::lround(config_.fov_deg / config_.resolution_deg)) + 1;
}

double Lms200Model::angle_min_rad() const { return -0.5 * config_.fov_deg * kDegToRad; }
double Lms200Model::angle_increment_rad() const { return config_.resolution_deg * kDegToRad; }
double Lms200Model::unit_m() const {
  return config_.range_mode == Lms200RangeMode::kCm ? 0.01 : 0.001;
}
double Lms200Model::max_range_m() const { return kMaxCountsInRange * unit_m(); }

int Lms200Model::interlaced_sweeps() const {
  return static_cast<int>(std::lround(1.0 / config_.resolution_deg));
}

double Lms200Model::measurement_time_s() const {
  // The last interlaced turn ends when its beam crosses the far edge of the field of view.
  return (interlaced_sweeps() - 1 + config_.fov_deg / 360.0) / kMirrorRate_hz;
}

int Lms200Model::telegram_bytes() const { return kTelegramOverheadBytes + 2 * readings_; }

double Lms200Model::transfer_time_s() const {
  return static_cast<double>(telegram_bytes()) * kBitsPerByte / config_.baud;
}

double Lms200Model::line_period_s() const {
  // Stop-scan-go asks for one line at a time: all interlaced turns, then the reply on the wire.
  return interlaced_sweeps() / kMirrorRate_hz + transfer_time_s();
}

double Lms200Model::NoiseSigma(double range_m, double incidence_rad) const {
  if (config_.noise_sigma_m <= 0.0) return 0.0;  // the ideal sensor
  const double r = std::max(range_m, 0.0);
  const double grow = config_.noise_per_m * r;
  const double tilt =
      std::tan(std::clamp(incidence_rad, 0.0, config_.incidence_noise_max_deg * kDegToRad));
  const double footprint =
      config_.incidence_noise_gain * r * config_.beam_divergence_deg * kDegToRad * tilt;
  return std::sqrt(config_.noise_sigma_m * config_.noise_sigma_m + grow * grow +
                   footprint * footprint);
}

double Lms200Model::DropoutProbability(double range_m, double incidence_rad) const {
  if (config_.noise_sigma_m <= 0.0) return 0.0;  // the ideal sensor
  const double start = config_.dropout_grazing_deg * kDegToRad;
  const double grazing = config_.dropout_grazing_at_90 *
                         std::clamp((incidence_rad - start) / (0.5 * kPi - start), 0.0, 1.0);
  const double far = config_.dropout_far_per_m * std::max(range_m - config_.dropout_far_m, 0.0);
  return std::min(grazing + far, 1.0);
}

void Lms200Model::Measure(const float* true_ranges, const float* edge_lo, const float* edge_hi,
                          LaserLine& line, const float* cos_incidence) {
  const auto n = static_cast<std::size_t>(readings_);
  line.angle_min_rad = angle_min_rad();
  line.angle_increment_rad = angle_increment_rad();
  line.duration_s = measurement_time_s();
  line.ranges_m.assign(n, std::numeric_limits<float>::quiet_NaN());
  line.status.assign(n, ReadingStatus::kNoReturn);
  const bool mix = config_.mixed_pixels && edge_lo != nullptr && edge_hi != nullptr;
  const double unit = unit_m();
  const double max_range = max_range_m();
  for (std::size_t i = 0; i < n; ++i) {
    double range = true_ranges[i];
    if (!std::isfinite(range)) continue;  // nothing hit: no return
    // A dropout draw for every hit, whatever its probability, so that switching an effect keeps
    // the draws of the others.
    const double u_drop = uniform_(effects_);
    if (mix && std::isfinite(edge_lo[i]) && std::isfinite(edge_hi[i])) {
      const double lo = std::min({range, double(edge_lo[i]), double(edge_hi[i])});
      const double hi = std::max({range, double(edge_lo[i]), double(edge_hi[i])});
      // A beam straddling a depth edge returns a blend of both surfaces.
      if (hi - lo > kMixedPixelJump_m) range = (range + edge_lo[i] + edge_hi[i]) / 3.0;
    }
    const double incidence =
        cos_incidence ? std::acos(std::clamp(double(cos_incidence[i]), 0.0, 1.0)) : 0.0;
    // Draw noise for every hit so the stream of draws does not depend on the range mode.
    const double noisy = range + config_.range_bias_m + NoiseSigma(range, incidence) * noise_(rng_);
    if (u_drop < DropoutProbability(range, incidence)) continue;  // no return
    if (range > max_range) {
      line.status[i] = ReadingStatus::kOverRange;
      continue;
    }
    const double counts = std::round(std::max(noisy, 0.0) / unit);
    if (counts >= kMaxCountsInRange) {
      line.status[i] = ReadingStatus::kOverRange;
      continue;
    }
    line.ranges_m[i] = static_cast<float>(counts * unit);
    line.status[i] = ReadingStatus::kValid;
  }
}

}  // namespace pitchlab::sensors
