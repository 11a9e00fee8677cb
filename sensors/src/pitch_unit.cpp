#include "pitchlab/sensors/pitch_unit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pitchlab::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;

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
}

PitchUnitModel::PitchUnitModel(const PitchUnitConfig& config) : config_(config) {
  config_.Validate();
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

double PitchUnitModel::MoveTime(double from_rad, double to_rad) const {
  return std::abs(to_rad - from_rad) / (config_.max_speed_dps * kDegToRad) + config_.settle_s;
}

}  // namespace pitchlab::sensors
