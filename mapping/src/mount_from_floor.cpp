#include "pitchlab/mapping/mount_from_floor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::mapping {
namespace {

// A floor point in its line's laser frame (nominal mount) and the line's encoder pitch.
struct FloorPoint {
  Eigen::Vector3d q;
  double gamma = 0;
};

sensors::MountConfig WithCorrection(const sensors::MountConfig& nominal,
                                    const Eigen::Vector3d& correction) {
  sensors::MountConfig m = nominal;
  m.misalignment_rpy_rad += correction;
  return m;
}

// The point's height in base_link on the mount `m`.
double HeightOn(const sensors::MountConfig& m, const FloorPoint& f) {
  return (m.BaseToLaser(f.gamma) * f.q).z();
}

// The band's points within 3 sigma of the floor: |z - floor_z| on the mount `m`.
std::vector<FloorPoint> Within(const std::vector<FloorPoint>& band, const sensors::MountConfig& m,
                               double floor_z, double threshold_m) {
  std::vector<FloorPoint> in;
  for (const FloorPoint& f : band)
    if (std::abs(HeightOn(m, f) - floor_z) < threshold_m) in.push_back(f);
  return in;
}

// The q-quantile of |x| for x ~ N(0, 1) (bisection on erf).
double HalfNormalQuantile(double q) {
  double lo = 0, hi = 10;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (std::erf(mid / std::sqrt(2.0)) < q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
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
                    std::to_string(level->tilt_rad * 180 / M_PI) +
                    " deg in base_link, more than a mount error (" +
                    std::to_string(config.max_tilt_rad * 180 / M_PI) + " deg)");
  }
  // The band's points, each back in its line's laser frame, and their distance from the plane.
  std::vector<FloorPoint> band;
  std::vector<double> distance;
  for (const sensors::ScanPoint& p : scan.points) {
    const Eigen::Vector3f at(p.x, p.y, p.z);
    if (p.line >= scan.lines.size() || !at.allFinite() || at.z() >= laser.z()) continue;
    const float r = (at - laser).head<2>().norm();
    if (r < config.ground.min_radius_m || r > config.ground.max_radius_m) continue;
    const double gamma = scan.lines[p.line].pitch_rad;
    band.push_back({nominal.BaseToLaser(gamma).inverse() * at.cast<double>(), gamma});
    distance.push_back(std::abs(level->normal.dot(at.cast<double>()) - level->offset_m));
  }
  if (band.size() < config.ground.min_points) {
    return Fail(Error::Code::kFailed, "mount calibration: " + std::to_string(band.size()) +
                                          " points of the scan's lines near the floor");
  }
  // The points' own scatter about the floor (the plane was fitted to cell medians, which scatter
  // less): the floor is at least the levelling's quantile of the band, so that quantile of the
  // distances is a Gaussian's with this sigma, as FitGroundLevel starts.
  const std::vector<double> near_plane = distance;
  const std::size_t q_index = static_cast<std::size_t>(config.ground.quantile * (band.size() - 1));
  std::nth_element(distance.begin(), distance.begin() + q_index, distance.end());
  double sigma_m =
      std::max(distance[q_index] / HalfNormalQuantile(config.ground.quantile), 1e-4);

  MountFromFloor out;
  out.tilt_before_rad = level->tilt_rad;
  out.residual_before_m = sigma_m;
  // The first floor: the band's points near the plane; later, those near level on the mount found.
  std::vector<FloorPoint> floor;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  // the correction's roll, pitch, yaw [rad]
  double floor_z = 0;                           // base_link z of the floor [m]
  const double prior_w = 1.0 / (config.prior_sigma_rad * config.prior_sigma_rad);
  Eigen::Matrix4d A = Eigen::Matrix4d::Identity();
  constexpr double kStep_rad = 1e-6;  // finite differences: heights move by ~4e-6 m
  for (int round = 0; round < 10; ++round) {
    if (round == 0) {
      for (std::size_t k = 0; k < band.size(); ++k)
        if (near_plane[k] < 3.0 * sigma_m) floor.push_back(band[k]);
      double sum = 0;
      for (const FloorPoint& f : floor) sum += HeightOn(nominal, f);
      floor_z = floor.empty() ? 0 : sum / floor.size();
    } else {
      floor = Within(band, WithCorrection(nominal, x), floor_z, 3.0 * sigma_m);
    }
    if (floor.size() < config.ground.min_points) {
      return Fail(Error::Code::kFailed, "mount calibration: only " +
                                            std::to_string(floor.size()) + " of " +
                                            std::to_string(band.size()) +
                                            " points near the laser lie on one level floor");
    }
    const std::size_t before = floor.size();
    // Gauss-Newton on (roll, pitch, yaw, floor z): the heights minus floor_z, with the prior.
    for (int iteration = 0; iteration < 20; ++iteration) {
      const sensors::MountConfig m = WithCorrection(nominal, x);
      std::array<sensors::MountConfig, 3> moved;
      for (int k = 0; k < 3; ++k) moved[k] = WithCorrection(nominal, x + kStep_rad * Eigen::Vector3d::Unit(k));
      A.setZero();
      Eigen::Vector4d b = Eigen::Vector4d::Zero();
      const double w = 1.0 / (sigma_m * sigma_m);
      for (const FloorPoint& f : floor) {
        const double z = HeightOn(m, f);
        Eigen::Vector4d J;
        for (int k = 0; k < 3; ++k) J[k] = (HeightOn(moved[k], f) - z) / kStep_rad;
        J[3] = -1.0;
        A.noalias() += w * J * J.transpose();
        b.noalias() -= w * J * (z - floor_z);
      }
      A.topLeftCorner<3, 3>().diagonal().array() += prior_w;
      b.head<3>() -= prior_w * x;
      const Eigen::Vector4d step = A.ldlt().solve(b);
      x += step.head<3>();
      floor_z += step[3];
      if (step.head<3>().norm() < 1e-9 && std::abs(step[3]) < 1e-7) break;
    }
    const sensors::MountConfig m = WithCorrection(nominal, x);
    double ss = 0;
    for (const FloorPoint& f : floor) ss += std::pow(HeightOn(m, f) - floor_z, 2);
    sigma_m = std::max(std::sqrt(ss / floor.size()), 1e-4);
    out.residual_m = sigma_m;
    if (round > 0 && Within(band, m, floor_z, 3.0 * sigma_m).size() == before) break;
  }
  if (!(x.norm() <= config.max_tilt_rad)) {
    return Fail(Error::Code::kFailed,
                "mount calibration: the floor asks for a mount " +
                    std::to_string(x.norm() * 180 / M_PI) + " deg off, more than a mount error (" +
                    std::to_string(config.max_tilt_rad * 180 / M_PI) + " deg)");
  }
  out.mount = WithCorrection(nominal, x);
  out.correction_rpy_rad = x;
  out.sigma_rpy_rad = A.inverse().diagonal().head<3>().cwiseSqrt();
  out.floor_z_m = floor_z;
  out.points = floor.size();
  return out;
}

}  // namespace pitchlab::mapping
