#include "pitchlab/sensors/grazing_returns.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include <Eigen/Eigenvalues>

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

// The footprint spread along the beam, r delta tan(incidence), on the surface that would join the
// return at `here` (range `range`, `beam` from the laser to it) to its in-line neighbour `q`:
// tan(incidence) = |dr| / (r dtheta) for beams dtheta apart, so the spread is delta |dr| / dtheta
// [m]; +inf for two beams along one line of sight.
double SpreadTowards(const Eigen::Vector3d& beam, float range, const ScanPoint& q,
                     const Eigen::Vector3d& here, const GrazingConfig& config) {
  const Eigen::Vector3d to_q = beam + (At(q) - here);
  const double dtheta = std::atan2(beam.cross(to_q).norm(), beam.dot(to_q));
  const double dr = std::abs(double(q.range_m) - double(range));
  if (!(dtheta > 0.0)) return std::numeric_limits<double>::infinity();
  return config.beam_divergence_rad * dr / dtheta;
}

// The unit normal of return i's surface: the least-squares plane of the returns of its beam and
// of its in-line neighbour on `side` (-1 or +1: the one nearest it in range, on its surface if
// any is: a pole's other beam, not the background), each in the lines before and after. On a
// surface met at grazing incidence the range noise moves each return along its beam, nearly in
// the surface: the points stay on it, but the vector to any one neighbour may be mostly that
// noise (a cross product of two of them turned a grazed wall into "ground"). Empty when those
// returns span no plane.
std::optional<Eigen::Vector3d> SurfaceNormal(const Scan3D& scan, const OrganisedIndex& index,
                                             std::size_t i, int side, const GrazingConfig& config) {
  const ScanPoint& p = scan.points[i];
  const std::int32_t neighbour = index(p.line, p.beam + side);
  // Ranges of the lines before and after on the same surface: lines and beams are ~0.5 deg
  // apart, so a neighbouring line meets a surface the beams meet obliquely about as far off in
  // range as the neighbouring beam does, and a facing one within the noise: twice that step,
  // plus a cell for the noise.
  const double same_surface =
      2.0 * std::abs(scan.points[std::size_t(neighbour)].range_m - p.range_m) + config.max_spread_m;
  Eigen::Vector3d window[6];
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int count = 0;
  for (int dl = -1; dl <= 1; ++dl) {
    for (const int db : {0, side}) {
      const std::int32_t k = index(p.line + dl, p.beam + db);
      if (k == kNone) continue;
      // The line before or after met another surface here (a pole's top, a jamb's edge).
      if (dl != 0 && std::abs(scan.points[std::size_t(k)].range_m - p.range_m) > same_surface) {
        continue;
      }
      window[count] = At(scan.points[std::size_t(k)]);
      mean += window[count++];
    }
  }
  if (count < 3) return std::nullopt;
  mean /= count;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int k = 0; k < count; ++k) cov += (window[k] - mean) * (window[k] - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  if (!(eig.eigenvalues()(1) > 0.0)) return std::nullopt;  // all on one line
  return eig.eigenvectors().col(0).normalized();
}

}  // namespace

std::vector<bool> GrazedReturns(const Scan3D& scan, const MountConfig& mount,
                                const GrazingConfig& config) {
  std::vector<bool> grazed(scan.points.size(), false);
  if (scan.points.empty()) return grazed;
  const OrganisedIndex index(scan);
  const double cos_ground = std::cos(config.max_ground_tilt_rad);
  const auto range = [&](std::int32_t k) { return scan.points[std::size_t(k)].range_m; };
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const ScanPoint& p = scan.points[i];
    const std::int32_t before = index(p.line, p.beam - 1), after = index(p.line, p.beam + 1);
    if (before == kNone && after == kNone) continue;
    const float r = p.range_m;
    // A neighbour that gave no return (a dropout, or the beam past a jamb into the open) counts
    // as beyond the return: the surface receded from it.
    const float inf = std::numeric_limits<float>::infinity();
    const float r_before = before != kNone ? range(before) : inf;
    const float r_after = after != kNone ? range(after) : inf;
    const bool between = (r_before - r) * (r_after - r) < 0.0f;
    // Nearer than both (or farther than both): a pole or a leg hit by a beam or two, with the
    // background on either side, whose lines before and after meet it at its own range; or the
    // end of a surface met at grazing incidence, whose returns scatter along their beams, in
    // its line and across lines alike, so that the next beam's return lies within that scatter
    // (a jamb's last return came 0.37 m short, in front of both neighbours, into the doorway).
    float across_scatter = 0.0f;
    for (const std::int32_t k : {index(p.line - 1, p.beam), index(p.line + 1, p.beam)}) {
      if (k != kNone) across_scatter = std::max(across_scatter, std::abs(range(k) - r));
    }
    const float step_before = std::abs(r_before - r), step_after = std::abs(r_after - r);
    if (!between && !(std::min(step_before, step_after) <= across_scatter)) continue;

    const Eigen::Vector3d here = At(p);
    const double pitch = p.line < scan.lines.size() ? scan.lines[p.line].pitch_rad : 0.0;
    const Eigen::Vector3d beam = here - mount.BaseToLaser(pitch).translation();
    const std::optional<Eigen::Vector3d> normal =
        SurfaceNormal(scan, index, i, step_before <= step_after ? -1 : 1, config);
    // Without a surface nothing tells a grazed wall from far ground, which is kept.
    if (!normal || std::abs(normal->z()) >= cos_ground) continue;  // ground: a slide keeps height

    // A mixed pixel: between two neighbours each so far off in range that no surface joins it
    // to them within a cell's spread, with the ranges jumping on both sides (a smooth surface
    // met at grazing incidence, a far floor, changes range gradually, each step within a factor
    // 2 of the next one out; the first return past a depth edge continues its surface on one
    // side).
    const auto jump = [&](std::int32_t inner, std::int32_t outer) {
      if (outer == kNone) return false;  // nothing to tell a jump by
      const float step_in = std::abs(range(inner) - r);
      const float step_out = std::abs(range(outer) - range(inner));
      return step_out < 0.5f * step_in || step_out > 2.0f * step_in;
    };
    if (between && before != kNone && after != kNone &&
        SpreadTowards(beam, r, scan.points[std::size_t(before)], here, config) >
            config.max_spread_m &&
        SpreadTowards(beam, r, scan.points[std::size_t(after)], here, config) >
            config.max_spread_m &&
        jump(before, index(p.line, p.beam - 2)) && jump(after, index(p.line, p.beam + 2))) {
      grazed[i] = true;
      continue;
    }
    const double b = beam.norm();
    if (!(b > 0.0)) continue;
    const double cos_incidence = std::abs(normal->dot(beam)) / b;
    const double sin_incidence = std::sqrt(std::max(0.0, 1.0 - cos_incidence * cos_incidence));
    // spread = r delta tan(incidence) > max, without dividing by a cosine that may be 0.
    grazed[i] =
        r * config.beam_divergence_rad * sin_incidence > config.max_spread_m * cos_incidence;
  }
  return grazed;
}

}  // namespace pitchlab::sensors
