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
  if (!(noise_sigma_m >= 0.0) || !std::isfinite(noise_sigma_m)) {
    Invalid("noise_sigma_m", noise_sigma_m, ">= 0");
  }
  if (!std::isfinite(range_bias_m)) Invalid("range_bias_m", range_bias_m, "a finite number");
  if (!(beam_divergence_deg >= 0.0 && beam_divergence_deg < 5.0)) {
    Invalid("beam_divergence_deg", beam_divergence_deg, "0 .. 5");
  }
  if (baud != 9600 && baud != 19200 && baud != 38400 && baud != 500000) {
    Invalid("baud", baud, "9600, 19200, 38400, 500000");
  }
}

Lms200Model::Lms200Model(const Lms200Config& config) : config_(config), rng_(config.seed) {
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

void Lms200Model::Measure(const float* true_ranges, const float* edge_lo, const float* edge_hi,
                          LaserLine& line) {
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
    if (mix && std::isfinite(edge_lo[i]) && std::isfinite(edge_hi[i]) && std::isfinite(range)) {
      const double lo = std::min({range, double(edge_lo[i]), double(edge_hi[i])});
      const double hi = std::max({range, double(edge_lo[i]), double(edge_hi[i])});
      // A beam straddling a depth edge returns a blend of both surfaces.
      if (hi - lo > kMixedPixelJump_m) range = (range + edge_lo[i] + edge_hi[i]) / 3.0;
    }
    if (!std::isfinite(range)) continue;  // nothing hit: no return
    // Draw noise for every hit so the stream of draws does not depend on the range mode.
    const double noisy = range + config_.range_bias_m + config_.noise_sigma_m * noise_(rng_);
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
