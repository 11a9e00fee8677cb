#include "pitchlab/mapping/line_pitch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>

#include "up_plane_fit.hpp"

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {
namespace {

// A point relative to the sensor turned about the pitch axis (y) by `angle` [rad].
Eigen::Vector3d TurnedAboutY(const Eigen::Vector3d& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z()};
}

// The scan's lines: indices of points of one elevation about the y axis through the sensor, each
// of at least min_line_points, and how many finite points there were.
std::vector<std::vector<std::uint32_t>> LinesOf(const std::vector<Eigen::Vector3f>& points,
                                                const Eigen::Vector3f& sensor,
                                                const LinePitchConfig& config,
                                                std::size_t* finite) {
  std::vector<std::pair<double, std::uint32_t>> elevation;
  elevation.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!points[k].allFinite()) continue;
    const Eigen::Vector3f v = points[k] - sensor;
    // On the axis itself (a beam along y) the elevation is undefined: such points join no line.
    if (std::hypot(v.x(), v.z()) < 1e-3f) continue;
    elevation.emplace_back(std::atan2(-static_cast<double>(v.z()), static_cast<double>(v.x())),
                           static_cast<std::uint32_t>(k));
  }
  *finite = elevation.size();
  std::sort(elevation.begin(), elevation.end());
  // A run of elevations is one line only when it spans no more than the gap itself: lines whose
  // elevation drifts along them (a laser off the pitch axis, a frame that is not the scanner's)
  // chain into wide runs, and those are no lines.
  std::vector<std::vector<std::uint32_t>> lines;
  std::vector<std::uint32_t> run;
  double run_first = 0;
  for (std::size_t k = 0; k <= elevation.size(); ++k) {
    if (k == elevation.size() ||
        (k > 0 && elevation[k].first - elevation[k - 1].first > config.line_gap_rad)) {
      const double span = k > 0 ? elevation[k - 1].first - run_first : 0.0;
      if (run.size() >= config.min_line_points && span <= config.line_gap_rad) lines.push_back(run);
      run.clear();
      if (k == elevation.size()) break;
    }
    if (run.empty()) run_first = elevation[k].first;
    run.push_back(elevation[k].second);
  }
  return lines;
}

// The angle of point `v` (relative to the sensor) within its line's plane, from straight ahead
// towards +y: an LMS200's beam angle, whose beams lie on multiples of its resolution [rad].
double BeamAngle(const Eigen::Vector3f& v) {
  return std::atan2(static_cast<double>(v.y()),
                    std::hypot(static_cast<double>(v.x()), static_cast<double>(v.z())));
}

// The lines' beam step: the median gap between neighbouring beam angles within a line (a
// reading missing, out of range, widens a gap; the median is the step) [rad]; 0 without any.
double BeamStep(const std::vector<std::vector<std::uint32_t>>& lines,
                const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& sensor) {
  std::vector<double> gaps, angles;
  for (const auto& line : lines) {
    angles.clear();
    for (const std::uint32_t k : line) angles.push_back(BeamAngle(points[k] - sensor));
    std::sort(angles.begin(), angles.end());
    // 1e-5 rad: twice the angle a 3DTK coordinate's six digits resolve at 1 m; closer beams are
    // one beam written twice.
    for (std::size_t i = 1; i < angles.size(); ++i)
      if (angles[i] - angles[i - 1] > 1e-5) gaps.push_back(angles[i] - angles[i - 1]);
  }
  if (gaps.empty()) return 0;
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

// Each line split into its `sweeps` interlaced sweeps (beam index, counted from straight ahead,
// modulo sweeps); `sweep_of` receives each piece's sweep. Pieces of fewer than min_line_points
// points are dropped, as LinesOf drops short lines.
std::vector<std::vector<std::uint32_t>> SplitSweeps(
    const std::vector<std::vector<std::uint32_t>>& lines,
    const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& sensor, double step,
    int sweeps, const LinePitchConfig& config, std::vector<int>& sweep_of) {
  std::vector<std::vector<std::uint32_t>> out;
  for (const auto& line : lines) {
    std::vector<std::vector<std::uint32_t>> pieces(static_cast<std::size_t>(sweeps));
    for (const std::uint32_t k : line) {
      const long beam = std::lround(BeamAngle(points[k] - sensor) / step);
      pieces[static_cast<std::size_t>(((beam % sweeps) + sweeps) % sweeps)].push_back(k);
    }
    for (int s = 0; s < sweeps; ++s) {
      if (pieces[s].size() < config.min_line_points) continue;
      out.push_back(std::move(pieces[s]));
      sweep_of.push_back(s);
    }
  }
  return out;
}

struct FloorPlane {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  // up normal
  double d = 0;                                  // n . v = d, v relative to the sensor
};

// Total least squares plane through `v`, normal turned up.
FloorPlane FitPlane(const std::vector<Eigen::Vector3d>& v) {
  const auto [n, d] = UpPlaneThrough(v);
  return FloorPlane{n, d};
}

// One line's floor candidates relative to the sensor, and the correction found for it.
struct Line {
  std::vector<std::uint32_t> all;         // every point of the line
  std::vector<Eigen::Vector3d> floor;     // its points in the floor band, relative to the sensor
  double correction_rad = 0;
  double lever_m = 0;  // mean |d e / d angle| of its floor points: how far ahead it meets the floor
  bool corrected = false;
  int sweep = 0;  // which interlaced sweep of its line it is (SplitSweeps)
};

// The correction of one line against `plane`: the angle most of its floor points agree on (the
// densest window of their individual angles, `tolerance_m` wide at their median lever), refined
// by least squares over the points then within tolerance_m of the plane. Returns the number of
// those points (0: no verdict).
std::size_t CorrectLine(Line& line, const FloorPlane& plane, double tolerance_m,
                        const LinePitchConfig& config) {
  // Angle at which each point would lie on the plane, to first order about the current turn.
  std::vector<double> angle, lever;
  for (const Eigen::Vector3d& v : line.floor) {
    const Eigen::Vector3d t = TurnedAboutY(v, line.correction_rad);
    const double a = plane.n.x() * t.z() - plane.n.z() * t.x();  // n . (y x t)
    if (std::abs(a) < 1e-3) continue;
    angle.push_back(line.correction_rad - (plane.n.dot(t) - plane.d) / a);
    lever.push_back(std::abs(a));
  }
  if (angle.size() < config.min_line_points) return 0;
  std::vector<double> sorted_lever = lever;
  std::nth_element(sorted_lever.begin(), sorted_lever.begin() + sorted_lever.size() / 2,
                   sorted_lever.end());
  const double width = 2 * tolerance_m / sorted_lever[sorted_lever.size() / 2];
  std::vector<double> sorted = angle;
  std::sort(sorted.begin(), sorted.end());
  std::size_t best = 0, best_begin = 0;
  for (std::size_t b = 0, e = 0; b < sorted.size(); ++b) {
    while (e < sorted.size() && sorted[e] - sorted[b] <= width) ++e;
    if (e - b > best) best = e - b, best_begin = b;
  }
  double guess = 0;
  for (std::size_t k = best_begin; k < best_begin + best; ++k) guess += sorted[k];
  guess /= static_cast<double>(best);
  // Least squares over the points within tolerance at the guess (Gauss-Newton, two steps).
  double angle_now = guess;
  std::size_t used = 0;
  for (int step = 0; step < 2; ++step) {
    double num = 0, den = 0, lever_sum = 0;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero(), sum_sq = Eigen::Vector2d::Zero();
    used = 0;
    for (const Eigen::Vector3d& v : line.floor) {
      const Eigen::Vector3d t = TurnedAboutY(v, angle_now);
      const double e = plane.n.dot(t) - plane.d;
      if (!(std::abs(e) <= tolerance_m)) continue;
      const double a = plane.n.x() * t.z() - plane.n.z() * t.x();
      num += a * e;
      den += a * a;
      lever_sum += std::abs(a);
      sum += t.head<2>();
      sum_sq += t.head<2>().cwiseProduct(t.head<2>());
      ++used;
    }
    if (used < config.min_line_points || den <= 0) return 0;
    // A pitched line meets the floor across the scan (along y, at one distance ahead); points
    // that line up along x are a wall's foot or an obstacle's, not the floor's trace.
    const Eigen::Vector2d var = sum_sq / used - (sum / used).cwiseProduct(sum / used);
    if (!(var.y() >= 9 * var.x())) return 0;
    angle_now -= num / den;
    line.lever_m = lever_sum / used;
  }
  if (!(std::abs(angle_now) <= config.max_correction_rad)) return 0;
  line.correction_rad = angle_now;
  return used;
}

// Each line's points that may be floor (relative to the sensor): below the sensor within the
// levelling's radii, and within what the largest correction could move onto `plane`.
std::vector<Line> FloorCandidates(const std::vector<std::vector<std::uint32_t>>& indices,
                                  const std::vector<Eigen::Vector3f>& points,
                                  const Eigen::Vector3f& sensor, const FloorPlane& plane,
                                  double sigma_m, const LinePitchConfig& config) {
  const double reach = std::tan(config.max_correction_rad);  // height per metre of range
  std::vector<Line> lines(indices.size());
  for (std::size_t l = 0; l < indices.size(); ++l) {
    lines[l].all = indices[l];
    for (const std::uint32_t k : indices[l]) {
      const Eigen::Vector3d v = (points[k] - sensor).cast<double>();
      const double r = std::hypot(v.x(), v.y());
      if (v.z() >= 0 || r < config.ground.min_radius_m || r > config.ground.max_radius_m) continue;
      const double e = plane.n.dot(v) - plane.d;
      if (std::abs(e) <= v.norm() * reach + 3 * sigma_m) {
        lines[l].floor.push_back(v);
      }
    }
  }
  return lines;
}

// The floor alone cannot tell two patterns of corrections from a change of the floor plane: one
// angle common to all lines (the frame's tilt about the axis) and angles that fall as 1 /
// distance ahead (the floor's height under the sensor). Those belong to the plane: the
// least-squares fit of the corrections by alpha + beta / lever is taken out of them, leaving the
// smallest corrections that flatten the floor.
void RemoveGauge(std::vector<Line>& lines) {
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  double mean = 0;
  std::size_t corrected = 0;
  for (const Line& line : lines) {
    if (!line.corrected) continue;
    const Eigen::Vector2d basis(1.0, 1.0 / line.lever_m);
    normal += basis * basis.transpose();
    rhs += basis * line.correction_rad;
    mean += line.correction_rad;
    ++corrected;
  }
  if (corrected == 0) return;
  const Eigen::Vector2d gauge = corrected >= 2 && std::abs(normal.determinant()) > 1e-12
                                    ? Eigen::Vector2d(normal.ldlt().solve(rhs))
                                    : Eigen::Vector2d(mean / corrected, 0.0);
  for (Line& line : lines) {
    if (line.corrected) line.correction_rad -= gauge.x() + gauge.y() / line.lever_m;
  }
}

// Alternates: each line onto the plane, then the plane through the corrected floor points. The
// tolerance starts at 3 sigma of the levelling's cell fit and becomes 3 sigma of the corrected
// floor points (the laser's own noise once the lines agree). Returns that sigma [m].
double AlignLinesToFloor(std::vector<Line>& lines, FloorPlane& plane, double sigma,
                         const LinePitchConfig& config) {
  for (int round = 0; round < 4; ++round) {
    const double tolerance = 3 * std::max(sigma, 1e-3);  // 1 mm: the LMS200's finest resolution
    for (Line& line : lines) {
      line.corrected = CorrectLine(line, plane, tolerance, config) > 0;
      if (!line.corrected) line.correction_rad = 0;
    }
    RemoveGauge(lines);
    std::vector<Eigen::Vector3d> floor;
    double sum_sq = 0;
    for (const Line& line : lines) {
      if (!line.corrected) continue;
      for (const Eigen::Vector3d& v : line.floor) {
        const Eigen::Vector3d t = TurnedAboutY(v, line.correction_rad);
        const double e = plane.n.dot(t) - plane.d;
        if (std::abs(e) > tolerance) continue;
        floor.push_back(t);
        sum_sq += e * e;
      }
    }
    if (floor.size() < 3) break;
    sigma = std::sqrt(sum_sq / static_cast<double>(floor.size()));
    plane = FitPlane(floor);
  }
  return sigma;
}

// Turns each of `indices`' lines about the y axis through `sensor_m` onto the floor; what was
// done goes into `out` (RectifyLinePitch).
void SetLinesRight(std::vector<Eigen::Vector3f>& points_m, const Eigen::Vector3f& sensor_m,
                   const std::vector<std::vector<std::uint32_t>>& indices,
                   const std::vector<int>& sweep_of, const LinePitchConfig& config,
                   LinePitch& out) {
  const Result<GroundLevel> level = FitGroundLevel(points_m, sensor_m, config.ground);
  if (!level) {
    out.note = level.error().message;
    return;
  }
  // The floor relative to the sensor.
  const FloorPlane first{level->normal,
                         level->offset_m - level->normal.dot(sensor_m.cast<double>())};
  FloorPlane plane = first;
  std::vector<Line> lines =
      FloorCandidates(indices, points_m, sensor_m, plane, level->residual_m, config);
  for (std::size_t l = 0; l < lines.size() && l < sweep_of.size(); ++l)
    lines[l].sweep = sweep_of[l];
  const double sigma = AlignLinesToFloor(lines, plane, level->residual_m, config);
  // Before and after, over the floor points of the corrected lines.
  double before = 0, after = 0, sum_sq = 0;
  std::size_t n = 0;
  for (const Line& line : lines) {
    if (!line.corrected) continue;
    ++out.corrected;
    sum_sq += line.correction_rad * line.correction_rad;
    out.max_correction_rad = std::max(out.max_correction_rad, std::abs(line.correction_rad));
    for (const Eigen::Vector3d& v : line.floor) {
      const double e = plane.n.dot(TurnedAboutY(v, line.correction_rad)) - plane.d;
      if (std::abs(e) > 3 * std::max(sigma, 1e-3)) continue;
      after += e * e;
      before += std::pow(first.n.dot(v) - first.d, 2);
      ++n;
    }
    std::vector<double> elevation;
    elevation.reserve(line.all.size());
    for (const std::uint32_t k : line.all) {
      const Eigen::Vector3d v = (points_m[k] - sensor_m).cast<double>();
      elevation.push_back(std::atan2(-v.z(), v.x()));
      points_m[k] = sensor_m + TurnedAboutY(v, line.correction_rad).cast<float>();
    }
    std::nth_element(elevation.begin(), elevation.begin() + elevation.size() / 2, elevation.end());
    out.line_corrections.push_back(
        {elevation[elevation.size() / 2], line.correction_rad, line.sweep});
  }
  std::sort(out.line_corrections.begin(), out.line_corrections.end(),
            [](const LineCorrection& a, const LineCorrection& b) {
              return a.pitch_rad != b.pitch_rad ? a.pitch_rad < b.pitch_rad : a.sweep < b.sweep;
            });
  if (out.corrected == 0) {
    out.note = "no line crossed the floor within " + NumberText(config.ground.max_radius_m) +
               " m in " + std::to_string(config.min_line_points) + " points";
    return;
  }
  out.rms_correction_rad = std::sqrt(sum_sq / static_cast<double>(out.corrected));
  if (n > 0) {
    out.floor_rms_before_m = std::sqrt(before / static_cast<double>(n));
    out.floor_rms_after_m = std::sqrt(after / static_cast<double>(n));
  }
}

}  // namespace

LinePitch RectifyLinePitch(std::vector<Eigen::Vector3f>& points_m, const Eigen::Vector3f& sensor_m,
                           const LinePitchConfig& config) {
  LinePitch out;
  std::size_t finite = 0;
  const std::vector<std::vector<std::uint32_t>> indices = LinesOf(points_m, sensor_m, config,
                                                                  &finite);
  std::size_t in_lines = 0;
  for (const auto& l : indices) in_lines += l.size();
  out.lines = indices.size();
  if (indices.size() < config.min_lines ||
      static_cast<double>(in_lines) < config.min_line_share * static_cast<double>(finite)) {
    out.note = "not a nodding scan about the frame's y axis through the sensor: " +
               std::to_string(in_lines) + " of " + std::to_string(finite) + " points in " +
               std::to_string(indices.size()) + " lines of one elevation each";
    return out;
  }
  out.nodding = true;
  const double step = BeamStep(indices, points_m, sensor_m);
  out.sweeps_per_line = sensors::InterlacedSweeps(step, config.sweep_step_rad);
  if (out.sweeps_per_line == 1) {
    SetLinesRight(points_m, sensor_m, indices, {}, config, out);
  } else {
    // A sweep holds a line's beams at `sweeps` times its step: the same floor span in as many
    // times fewer points.
    LinePitchConfig per_sweep = config;
    per_sweep.min_line_points =
        (config.min_line_points + out.sweeps_per_line - 1) / out.sweeps_per_line;
    std::vector<int> sweep_of;
    const std::vector<std::vector<std::uint32_t>> sweeps =
        SplitSweeps(indices, points_m, sensor_m, step, out.sweeps_per_line, per_sweep, sweep_of);
    SetLinesRight(points_m, sensor_m, sweeps, sweep_of, per_sweep, out);
  }
  return out;
}

LinePitch RectifyLinePitch(std::vector<Eigen::Vector3f>& points_m, const Eigen::Vector3f& axis_m,
                           const std::vector<std::vector<std::uint32_t>>& lines,
                           const LinePitchConfig& config, const std::vector<int>& sweep_of) {
  if (!sweep_of.empty() && sweep_of.size() != lines.size()) {
    throw std::invalid_argument("RectifyLinePitch: " + std::to_string(sweep_of.size()) +
                                " sweeps given for " + std::to_string(lines.size()) + " lines");
  }
  LinePitch out;
  std::vector<std::vector<std::uint32_t>> kept;
  std::vector<int> kept_sweep;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const auto& line = lines[l];
    for (const std::uint32_t k : line) {
      if (k >= points_m.size()) {
        throw std::invalid_argument("RectifyLinePitch: point index " + std::to_string(k) +
                                    " of " + std::to_string(points_m.size()));
      }
    }
    if (line.size() < config.min_line_points) continue;
    kept.push_back(line);
    if (!sweep_of.empty()) kept_sweep.push_back(sweep_of[l]);
  }
  out.lines = kept.size();
  out.nodding = true;
  SetLinesRight(points_m, axis_m, kept, kept_sweep, config, out);
  return out;
}

}  // namespace pitchlab::mapping
