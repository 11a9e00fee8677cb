#include "pitchlab/sensors/grazing_returns.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pitchlab::sensors {
namespace {

constexpr std::int32_t kNone = -1;

// The points of a scan by (line, beam): kNone where that reading gave no return.
class OrganisedIndex {
 public:
  explicit OrganisedIndex(const Scan3D& scan) {
    for (const ScanPoint& p : scan.points) {
      lines_ = std::max(lines_, int(p.line) + 1);
      beams_ = std::max(beams_, int(p.beam) + 1);
    }
    at_.assign(std::size_t(lines_) * std::size_t(beams_), kNone);
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      const ScanPoint& p = scan.points[i];
      at_[std::size_t(p.line) * std::size_t(beams_) + p.beam] = std::int32_t(i);
    }
  }
  std::int32_t operator()(int line, int beam) const {
    if (line < 0 || beam < 0 || line >= lines_ || beam >= beams_) return kNone;
    return at_[std::size_t(line) * std::size_t(beams_) + std::size_t(beam)];
  }

 private:
  int lines_ = 0, beams_ = 0;
  std::vector<std::int32_t> at_;
};

Eigen::Vector3d At(const ScanPoint& p) { return {p.x, p.y, p.z}; }

}  // namespace

std::vector<bool> GrazedReturns(const Scan3D& scan, const MountConfig& mount,
                                const GrazingConfig& config) {
  std::vector<bool> grazed(scan.points.size(), false);
  if (scan.points.empty()) return grazed;
  const OrganisedIndex index(scan);
  const double cos_ground = std::cos(config.max_ground_tilt_rad);
  // The neighbour of `i` among a and b whose range is nearest i's: on i's surface if any is.
  const auto nearer = [&](std::size_t i, std::int32_t a, std::int32_t b) -> std::int32_t {
    const float r = scan.points[i].range_m;
    if (a == kNone) return b;
    if (b == kNone) return a;
    return std::abs(scan.points[std::size_t(a)].range_m - r) <=
                   std::abs(scan.points[std::size_t(b)].range_m - r)
               ? a
               : b;
  };
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const ScanPoint& p = scan.points[i];
    const std::int32_t before = index(p.line, p.beam - 1), after = index(p.line, p.beam + 1);
    if (before == kNone || after == kNone) continue;
    const float r_before = scan.points[std::size_t(before)].range_m;
    const float r_after = scan.points[std::size_t(after)].range_m;
    if ((r_before - p.range_m) * (r_after - p.range_m) >= 0.0f) continue;  // not between them
    const std::int32_t across = nearer(i, index(p.line - 1, p.beam), index(p.line + 1, p.beam));
    if (across == kNone) continue;
    const Eigen::Vector3d here = At(p);
    const Eigen::Vector3d along = At(scan.points[std::size_t(nearer(i, before, after))]) - here;
    const Eigen::Vector3d normal = along.cross(At(scan.points[std::size_t(across)]) - here);
    const double n = normal.norm();
    if (!(n > 0.0)) continue;
    if (std::abs(normal.z()) / n >= cos_ground) continue;  // ground: a slide keeps its height
    const double pitch = p.line < scan.lines.size() ? scan.lines[p.line].pitch_rad : 0.0;
    const Eigen::Vector3d beam = here - mount.BaseToLaser(pitch).translation();
    const double b = beam.norm();
    if (!(b > 0.0)) continue;
    const double cos_incidence = std::abs(normal.dot(beam)) / (n * b);
    const double sin_incidence = std::sqrt(std::max(0.0, 1.0 - cos_incidence * cos_incidence));
    // spread = r delta tan(incidence) > max, without dividing by a cosine that may be 0.
    grazed[i] = p.range_m * config.beam_divergence_rad * sin_incidence >
                config.max_spread_m * cos_incidence;
  }
  return grazed;
}

}  // namespace pitchlab::sensors
