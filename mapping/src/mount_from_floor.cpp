#include "pitchlab/mapping/mount_from_floor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/sensors/number_text.hpp"

#include "half_normal_quantile.hpp"

namespace pitchlab::mapping {
namespace {

// A floor point in its line's laser frame (nominal mount) and its line's index.
struct FloorPoint {
  Eigen::Vector3d q;
  std::size_t line = 0;
};

sensors::MountConfig WithCorrection(const sensors::MountConfig& nominal,
                                    const Eigen::Vector3d& correction) {
  sensors::MountConfig m = nominal;
  m.misalignment_rpy_rad += correction;
  return m;
}

// Each line's laser frame in base_link on the mount `nominal` + `correction`: built once per
// line (a scan's ~200), not per point, for every evaluation of the heights.
std::vector<Eigen::Isometry3d> LineFrames(const sensors::Scan3D& scan,
                                          const sensors::MountConfig& nominal,
                                          const Eigen::Vector3d& correction) {
  const sensors::MountConfig m = WithCorrection(nominal, correction);
  std::vector<Eigen::Isometry3d> frames(scan.lines.size());
  for (std::size_t l = 0; l < frames.size(); ++l) frames[l] = m.BaseToLaser(scan.lines[l].pitch_rad);
  return frames;
}

// The point's height in base_link with its line's frame from `frames`.
double HeightOn(const std::vector<Eigen::Isometry3d>& frames, const FloorPoint& f) {
  return (frames[f.line] * f.q).z();
}

// The band's points within `threshold_m` of the level floor at floor_z, with the lines' `frames`.
std::vector<FloorPoint> Within(const std::vector<FloorPoint>& band,
                               const std::vector<Eigen::Isometry3d>& frames, double floor_z,
                               double threshold_m) {
  std::vector<FloorPoint> in;
  for (const FloorPoint& f : band)
    if (std::abs(HeightOn(frames, f) - floor_z) < threshold_m) in.push_back(f);
  return in;
}

// The floor band's points (below the laser, 0.5-4 m from it), each back in its line's laser
// frame, and their distances from the levelling's plane [m].
struct Band {
  std::vector<FloorPoint> points;
  std::vector<double> distance;
};

Band FloorBand(const sensors::Scan3D& scan, const sensors::MountConfig& nominal,
               const Eigen::Vector3f& laser, const GroundLevel& level,
               const GroundLevelConfig& ground) {
  Band band;
  const std::vector<Eigen::Isometry3d> frames = LineFrames(scan, nominal, Eigen::Vector3d::Zero());
  for (const sensors::ScanPoint& p : scan.points) {
    const Eigen::Vector3f at(p.x, p.y, p.z);
    if (p.line >= scan.lines.size() || !at.allFinite() || at.z() >= laser.z()) continue;
    const float r = (at - laser).head<2>().norm();
    if (r < ground.min_radius_m || r > ground.max_radius_m) continue;
    band.points.push_back({frames[p.line].inverse() * at.cast<double>(), p.line});
    band.distance.push_back(std::abs(level.normal.dot(at.cast<double>()) - level.offset_m));
  }
  return band;
}

// The unknowns: the correction's roll, pitch, yaw [rad], the floor's base_link z [m], and the
// normal matrix of the last solve (its inverse their covariance).
struct Solution {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  double floor_z = 0;
  Eigen::Matrix4d A = Eigen::Matrix4d::Identity();
};

// Gauss-Newton on the heights of `floor` minus floor_z, weighted by 1 / sigma^2, with the prior
// `prior_w` (1 / sigma^2 per angle) pulling the angles to zero; from `s`, in place.
void SolveLevel(const std::vector<FloorPoint>& floor, const sensors::Scan3D& scan,
                const sensors::MountConfig& nominal, double sigma_m, double prior_w,
                Solution& s) {
  constexpr double kStep_rad = 1e-6;  // finite differences: heights move by ~4e-6 m
  const double w = 1.0 / (sigma_m * sigma_m);
  for (int iteration = 0; iteration < 20; ++iteration) {
    const std::vector<Eigen::Isometry3d> frames = LineFrames(scan, nominal, s.x);
    std::array<std::vector<Eigen::Isometry3d>, 3> moved;
    for (int k = 0; k < 3; ++k)
      moved[k] = LineFrames(scan, nominal, s.x + kStep_rad * Eigen::Vector3d::Unit(k));
    s.A.setZero();
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    for (const FloorPoint& f : floor) {
      const double z = HeightOn(frames, f);
      Eigen::Vector4d J;
      for (int k = 0; k < 3; ++k) J[k] = (HeightOn(moved[k], f) - z) / kStep_rad;
      J[3] = -1.0;
      s.A.noalias() += w * J * J.transpose();
      b.noalias() -= w * J * (z - s.floor_z);
    }
    s.A.topLeftCorner<3, 3>().diagonal().array() += prior_w;
    b.head<3>() -= prior_w * s.x;
    const Eigen::Vector4d step = s.A.ldlt().solve(b);
    s.x += step.head<3>();
    s.floor_z += step[3];
    if (step.head<3>().norm() < 1e-9 && std::abs(step[3]) < 1e-7) break;
  }
}

// RMS of the heights of `floor` about floor_z on the mount `m` [m], at least 1e-4 m (far below
// any laser's noise: keeps a noise-free synthetic floor's threshold above rounding).
double RmsHeight(const std::vector<FloorPoint>& floor, const std::vector<Eigen::Isometry3d>& frames,
                 double floor_z) {
  double ss = 0;
  for (const FloorPoint& f : floor) ss += std::pow(HeightOn(frames, f) - floor_z, 2);
  return std::max(std::sqrt(ss / std::max<std::size_t>(floor.size(), 1)), 1e-4);
}

}  // namespace

Result<MountFromFloor> CalibrateMountFromFloor(const sensors::Scan3D& scan,
                                               const sensors::MountConfig& nominal,
                                               const MountFromFloorConfig& config) {
  if (scan.lines.empty()) {
    return Fail(Error::Code::kInvalidArgument,
                "mount calibration: the scan holds no lines (their pitch is what it needs)");
  }
  const Eigen::Vector3f laser = nominal.BaseToLaser(0.0).translation().cast<float>();
  Result<GroundLevel> level = FitGroundLevel(CloudFromScan(scan), laser, config.ground);
  if (!level) return tl::make_unexpected(level.error());
  if (!(level->tilt_rad <= config.max_tilt_rad)) {
    return Fail(Error::Code::kFailed,
                "mount calibration: the floor at the start tilts " +
                    NumberText(level->tilt_rad * 180 / M_PI) +
                    " deg in base_link, more than a mount error (" +
                    NumberText(config.max_tilt_rad * 180 / M_PI) + " deg)");
  }
  Band band = FloorBand(scan, nominal, laser, *level, config.ground);
  if (band.points.size() < config.ground.min_points) {
    return Fail(Error::Code::kFailed, "mount calibration: " + std::to_string(band.points.size()) +
                                          " points of the scan's lines near the floor");
  }
  // The points' own scatter about the floor (the plane was fitted to cell medians, which scatter
  // less): the floor is at least the levelling's quantile of the band, so that quantile of the
  // distances is a Gaussian's with this sigma, as FitGroundLevel starts.
  std::vector<double> sorted = band.distance;
  const std::size_t q = static_cast<std::size_t>(config.ground.quantile * (sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + q, sorted.end());
  double sigma_m = std::max(sorted[q] / HalfNormalQuantile(config.ground.quantile), 1e-4);

  MountFromFloor out;
  out.tilt_before_rad = level->tilt_rad;
  out.residual_before_m = sigma_m;
  // The first floor: the band's points near the plane; then those near level on the mount found,
  // until they stop changing.
  std::vector<FloorPoint> floor;
  for (std::size_t k = 0; k < band.points.size(); ++k)
    if (band.distance[k] < 3.0 * sigma_m) floor.push_back(band.points[k]);
  Solution s;
  const std::vector<Eigen::Isometry3d> nominal_frames =
      LineFrames(scan, nominal, Eigen::Vector3d::Zero());
  for (const FloorPoint& f : floor) s.floor_z += HeightOn(nominal_frames, f) / floor.size();
  const double prior_w = 1.0 / (config.prior_sigma_rad * config.prior_sigma_rad);
  for (int round = 0; round < 10; ++round) {
    if (floor.size() < config.ground.min_points) {
      return Fail(Error::Code::kFailed, "mount calibration: only " +
                                            std::to_string(floor.size()) + " of " +
                                            std::to_string(band.points.size()) +
                                            " points near the laser lie on one level floor");
    }
    SolveLevel(floor, scan, nominal, sigma_m, prior_w, s);
    const std::vector<Eigen::Isometry3d> frames = LineFrames(scan, nominal, s.x);
    sigma_m = RmsHeight(floor, frames, s.floor_z);
    std::vector<FloorPoint> next = Within(band.points, frames, s.floor_z, 3.0 * sigma_m);
    const bool settled = round > 0 && next.size() == floor.size();
    if (settled) break;
    floor = std::move(next);
  }
  if (!(s.x.norm() <= config.max_tilt_rad)) {
    return Fail(Error::Code::kFailed,
                "mount calibration: the floor asks for a mount " +
                    NumberText(s.x.norm() * 180 / M_PI) +
                    " deg off, more than a mount error (" +
                    NumberText(config.max_tilt_rad * 180 / M_PI) + " deg)");
  }
  out.mount = WithCorrection(nominal, s.x);
  out.correction_rpy_rad = s.x;
  out.sigma_rpy_rad = s.A.inverse().diagonal().head<3>().cwiseSqrt();
  out.floor_z_m = s.floor_z;
  out.residual_m = sigma_m;
  out.points = floor.size();
  return out;
}

}  // namespace pitchlab::mapping
