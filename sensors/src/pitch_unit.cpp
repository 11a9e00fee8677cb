#include "pitchlab/sensors/pitch_unit.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace pitchlab::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
// Streams of the seed for the error's phase and for each of its steps.
constexpr std::uint64_t kPhaseStream = 0x452821E638D01377ULL;
constexpr std::uint64_t kStepStream = 0xBE5466CF34E90C6CULL;

[[noreturn]] void Invalid(const char* field, double value, const char* allowed) {
  std::ostringstream os;
  os << "pitch_unit." << field << " = " << value << " is invalid (" << allowed << ")";
  throw std::invalid_argument(os.str());
}

}  // namespace

void PitchUnitConfig::Validate() const {
  if (!(step_deg > 0.0 && step_deg <= 10.0)) Invalid("step_deg", step_deg, "0 < step <= 10");
  if (encoder_counts_per_rev < 16) {
    Invalid("encoder_counts_per_rev", encoder_counts_per_rev, "at least 16");
  }
  if (!(min_deg < max_deg)) Invalid("min_deg", min_deg, "must be below max_deg");
  if (!(min_deg >= -180.0 && max_deg <= 180.0)) Invalid("max_deg", max_deg, "within +-180");
  if (!(max_speed_dps > 0.0)) Invalid("max_speed_dps", max_speed_dps, "> 0");
  if (!(settle_s >= 0.0)) Invalid("settle_s", settle_s, ">= 0");
  if (!(line_pitch_error_deg >= 0.0 && line_pitch_error_deg <= 10.0)) {
    Invalid("line_pitch_error_deg", line_pitch_error_deg, "0 .. 10");
  }
  if (!(line_pitch_error_period_deg > 0.0 && line_pitch_error_period_deg <= 90.0)) {
    Invalid("line_pitch_error_period_deg", line_pitch_error_period_deg, "0 < period <= 90");
  }
  if (!(sweep_lag_deg >= 0.0 && sweep_lag_deg <= 5.0)) {
    Invalid("sweep_lag_deg", sweep_lag_deg, "0 .. 5");
  }
}

PitchUnitModel::PitchUnitModel(const PitchUnitConfig& config) : config_(config) {
  config_.Validate();
  std::mt19937_64 rng(config_.seed ^ kPhaseStream);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  phase_rad_ = 2.0 * kPi * unit(rng);
  offset_rad_ = config_.line_pitch_error_period_deg * kDegToRad * unit(rng);
}

int PitchUnitModel::StepFor(double pitch_rad) const {
  // Only whole steps inside the mechanical limits exist.
  const double step_rad = config_.step_deg * kDegToRad;
  const int lo = static_cast<int>(std::ceil(config_.min_deg * kDegToRad / step_rad - 1e-9));
  const int hi = static_cast<int>(std::floor(config_.max_deg * kDegToRad / step_rad + 1e-9));
  const long nearest = std::lround(pitch_rad / step_rad);
  return static_cast<int>(std::clamp<long>(nearest, lo, hi));
}

double PitchUnitModel::StepAngle(int step) const { return step * config_.step_deg * kDegToRad; }

double PitchUnitModel::EncoderAngle(double pitch_rad) const {
  const double count_rad = 2.0 * kPi / config_.encoder_counts_per_rev;
  return std::round(pitch_rad / count_rad) * count_rad;
}

double PitchUnitModel::LinePitchError(double pitch_rad) const {
  if (config_.line_pitch_error_deg <= 0.0) return 0.0;
  const double period = config_.line_pitch_error_period_deg * kDegToRad;
  // The step's level: a normal draw of its own, from the step's index, so the error at a pitch
  // never depends on which pitches were asked before.
  const auto index = static_cast<std::int64_t>(std::floor((pitch_rad - offset_rad_) / period));
  std::mt19937_64 rng(config_.seed ^ kStepStream ^
                      (static_cast<std::uint64_t>(index) * 0x9E3779B97F4A7C15ULL));
  const double level = std::normal_distribution<double>(0.0, 1.0)(rng);
  // sin has variance 1/2, level / sqrt(2) too: RMS line_pitch_error_deg in all.
  const double unit =
      std::sin(2.0 * kPi * pitch_rad / period + phase_rad_) + level / std::sqrt(2.0);
  return config_.line_pitch_error_deg * kDegToRad * unit;
}

double PitchUnitModel::ReportedAngle(double pitch_rad) const {
  return EncoderAngle(pitch_rad + LinePitchError(pitch_rad));
}

double PitchUnitModel::MoveTime(double from_rad, double to_rad) const {
  return std::abs(to_rad - from_rad) / (config_.max_speed_dps * kDegToRad) + config_.settle_s;
}

}  // namespace pitchlab::sensors
