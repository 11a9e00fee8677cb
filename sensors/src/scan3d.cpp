#include "pitchlab/sensors/scan3d.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pitchlab::sensors {

Eigen::Isometry3d MountConfig::MountToLaser() const {
  const Eigen::Vector3d& rpy = misalignment_rpy_rad;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(t_mount_laser_m);
  T.rotate(Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()));
  return T;
}

Eigen::Isometry3d MountConfig::BaseToLaser(double gamma_rad) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(t_base_mount_m);
  T.rotate(Eigen::AngleAxisd(gamma_rad, Eigen::Vector3d::UnitY()));  // R_y(gamma) of Eq. 1
  return T * MountToLaser();
}

Eigen::Vector3d BeamPointInBase(double rho_m, double theta_rad, double gamma_rad,
                                const MountConfig& mount) {
  // Eq. 1: p = R_y(gamma) [rho cos(theta), rho sin(theta), 0]^T, with the mirror offset and the
  // misalignment inside the pitching frame and the mount's translation outside it.
  const Eigen::Vector3d in_plane(rho_m * std::cos(theta_rad), rho_m * std::sin(theta_rad), 0.0);
  return mount.BaseToLaser(gamma_rad) * in_plane;
}

double MaxTurnToLast(const std::vector<Eigen::Quaterniond>& attitudes) {
  double max_rad = 0;
  for (const Eigen::Quaterniond& q : attitudes) {
    max_rad = std::max(max_rad, Eigen::AngleAxisd(attitudes.back().conjugate() * q).angle());
  }
  return max_rad;
}

Scan3D AssembleScan(std::vector<LaserLine> lines, const MountConfig& mount,
                    const std::vector<Eigen::Quaterniond>& attitudes) {
  if (!attitudes.empty() && attitudes.size() != lines.size()) {
    throw std::invalid_argument("AssembleScan: " + std::to_string(attitudes.size()) +
                                " attitudes for " + std::to_string(lines.size()) +
                                " lines (one per line, or none)");
  }
  Scan3D scan;
  scan.deskewed = !attitudes.empty();
  scan.deskew_max_rad = MaxTurnToLast(attitudes);
  // The mirror at zero pitch: as the laser nods it swings on its arm from the pitch axis (9 cm by
  // default, so a few cm over the sweep), negligible against ray lengths of metres.
  scan.sensor_origin = mount.t_base_mount_m + mount.t_mount_laser_m;
  if (!lines.empty()) {
    scan.stamp_s = lines.front().stamp_s;
    const LaserLine& last = lines.back();
    scan.duration_s = last.stamp_s + last.duration_s - scan.stamp_s;
  }
  std::size_t readings = 0;
  for (const LaserLine& line : lines) readings += line.ranges_m.size();
  scan.points.reserve(readings);
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const LaserLine& line = lines[l];
    Eigen::Isometry3d T_base_laser = mount.BaseToLaser(line.pitch_rad);
    if (scan.deskewed) {
      // Rotation only, about base_link's origin: the base rocks about a tyre's contact a few
      // decimetres away, which moves the laser by millimetres per degree; the turn itself moves
      // far returns by centimetres per degree.
      const Eigen::Quaterniond to_last = attitudes.back().conjugate() * attitudes[l];
      T_base_laser.prerotate(to_last.normalized().toRotationMatrix());
    }
    for (std::size_t i = 0; i < line.ranges_m.size(); ++i) {
      switch (line.status[i]) {
        case ReadingStatus::kValid:
          break;
        case ReadingStatus::kOverRange:
          ++scan.over_ranges;
          continue;
        default:
          ++scan.no_returns;
          continue;
      }
      const double rho = line.ranges_m[i];
      const double theta = line.Angle(i);
      const Eigen::Vector3d p =
          T_base_laser * Eigen::Vector3d(rho * std::cos(theta), rho * std::sin(theta), 0.0);
      ScanPoint& q = scan.points.emplace_back();
      q.x = static_cast<float>(p.x());
      q.y = static_cast<float>(p.y());
      q.z = static_cast<float>(p.z());
      q.range_m = line.ranges_m[i];
      q.line = static_cast<std::uint16_t>(l);
      q.beam = static_cast<std::uint16_t>(i);
      q.stamp_s = line.stamp_s;
    }
  }
  scan.lines = std::move(lines);
  return scan;
}

void ReassembleScan(Scan3D& scan, const MountConfig& from, const MountConfig& to) {
  std::vector<Eigen::Isometry3d> from_to(scan.lines.size());
  for (std::size_t l = 0; l < scan.lines.size(); ++l) {
    const double gamma = scan.lines[l].pitch_rad;
    from_to[l] = to.BaseToLaser(gamma) * from.BaseToLaser(gamma).inverse();
  }
  for (const ScanPoint& p : scan.points) {
    if (p.line >= from_to.size()) {
      throw std::invalid_argument("ReassembleScan: a point of line " + std::to_string(p.line) +
                                  " in a scan of " + std::to_string(from_to.size()) + " lines");
    }
  }
  for (ScanPoint& p : scan.points) {
    const Eigen::Vector3d q = from_to[p.line] * Eigen::Vector3d(p.x, p.y, p.z);
    p.x = static_cast<float>(q.x());
    p.y = static_cast<float>(q.y());
    p.z = static_cast<float>(q.z());
  }
  if (scan.sensor_origin) {
    *scan.sensor_origin += (to.t_base_mount_m + to.t_mount_laser_m) -
                           (from.t_base_mount_m + from.t_mount_laser_m);
  }
}

}  // namespace pitchlab::sensors
