#include "pitchlab/sensors/pitching_scanner.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pitchlab::sensors {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

}  // namespace

void ScanPatternConfig::Validate() const {
  std::ostringstream os;
  if (lines < 1 || lines > 65535) {
    os << "scan.lines = " << lines << " is invalid (1 .. 65535)";
  } else if (!std::isfinite(pitch_start_deg) || std::abs(pitch_start_deg) > 180.0) {
    os << "scan.pitch_start_deg = " << pitch_start_deg << " is invalid (within +-180)";
  } else if (!std::isfinite(pitch_end_deg) || std::abs(pitch_end_deg) > 180.0) {
    os << "scan.pitch_end_deg = " << pitch_end_deg << " is invalid (within +-180)";
  } else if (line_timeout_ms <= 0) {
    os << "scan.line_timeout_ms = " << line_timeout_ms << " is invalid (> 0)";
  } else {
    return;
  }
  throw std::invalid_argument(os.str());
}

PitchingScanSource::PitchingScanSource(LineScanner& scanner, PitchAxis& axis,
                                       ScanPatternConfig pattern, MountConfig mount)
    : scanner_(scanner), axis_(axis), pattern_(pattern), mount_(std::move(mount)) {
  pattern_.Validate();
}

Result<Scan3D> PitchingScanSource::Acquire() {
  const std::chrono::milliseconds timeout(pattern_.line_timeout_ms);
  const int n = pattern_.lines;
  const double step_deg = n > 1 ? (pattern_.pitch_end_deg - pattern_.pitch_start_deg) / (n - 1) : 0;
  std::vector<LaserLine> lines;
  lines.reserve(static_cast<std::size_t>(n));
  std::vector<Eigen::Quaterniond> attitudes;
  bool attitude_known = static_cast<bool>(attitude_);
  // The scanner's sweep, ended on every way out: its lines kept once all are in, else dropped.
  struct Sweep {
    LineScanner& scanner;
    bool ended = false;
    ~Sweep() {
      if (!ended) scanner.EndSweep(nullptr);
    }
  } sweep{scanner_};
  scanner_.BeginSweep();
  for (int k = 0; k < n; ++k) {
    const double target_rad = (pattern_.pitch_start_deg + k * step_deg) * kDegToRad;
    Result<double> encoder_rad = axis_.MoveTo(target_rad, timeout);
    if (!encoder_rad) {
      return Fail(encoder_rad.error().code,
                  "pitch axis, line " + std::to_string(k) + ": " + encoder_rad.error().message);
    }
    Result<LaserLine> line = scanner_.NextLine(timeout);
    if (!line) {
      return Fail(line.error().code,
                  "laser, line " + std::to_string(k) + ": " + line.error().message);
    }
    // Eq. 1 uses the angle the encoder read, not the one commanded.
    line->pitch_rad = *encoder_rad;
    lines.push_back(std::move(*line));
    if (attitude_known) {
      const std::optional<Eigen::Quaterniond> q = attitude_();
      attitude_known = q.has_value();
      if (q) attitudes.push_back(*q);
    }
    if (progress_) progress_(k + 1, n);
  }
  sweep.ended = true;
  scanner_.EndSweep(&lines);
  if (!attitude_known) attitudes.clear();  // a line without one: the scan stays as swept
  const double sensed_rad = MaxTurnToLast(attitudes);
  if (sensed_rad < min_rotation_rad_) attitudes.clear();  // within the sensor's own error
  Scan3D scan = AssembleScan(std::move(lines), mount_, attitudes);
  scan.deskew_max_rad = sensed_rad;
  return scan;
}

}  // namespace pitchlab::sensors
