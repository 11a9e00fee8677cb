#include "pitchlab/mission/elevation_scan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/sensors/lms200.hpp"

namespace pitchlab::mission {

ElevationScan ElevationScanOf(const sensors::Scan3D& scan, double map_range_m,
                              const sensors::MountConfig& mount, double beam_divergence_rad,
                              double cell_m) {
  // The ground known under the robot: half its 0.4 m footprint each way, at the map's 0.1 m cell.
  constexpr double kFootprintHalf_m = 0.2, kStep_m = 0.1;
  ElevationScan out;
  out.points_base.reserve(scan.points.size());
  out.sensor_base = mount.BaseToLaser(0.0).translation().cast<float>();
  sensors::GrazingConfig grazing;
  grazing.beam_divergence_rad = beam_divergence_rad;
  grazing.max_spread_m = cell_m;
  const std::vector<bool> grazed = sensors::GrazedReturns(scan, mount, grazing);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const sensors::ScanPoint& p = scan.points[i];
    if (p.range_m > map_range_m) continue;
    if (grazed[i]) {
      ++out.grazed;
      continue;
    }
    out.points_base.emplace_back(p.x, p.y, p.z);
  }
  for (double x = -kFootprintHalf_m; x <= kFootprintHalf_m + 1e-9; x += kStep_m) {
    for (double y = -kFootprintHalf_m; y <= kFootprintHalf_m + 1e-9; y += kStep_m) {
      out.ground_base.emplace_back(float(x), float(y), 0.0f);
    }
  }
  return out;
}

mapping::LinePitch SetLinesRight(sensors::Scan3D& scan, const sensors::MountConfig& mount) {
  mapping::PointCloud points = mapping::CloudFromScan(scan);
  // A line finer than the LMS200's 1 deg turn is that many interlaced sweeps, at pitches of their
  // own when the unit moves during the line (sensors::InterlacedSweeps): each is set right on its
  // own, from as many times fewer floor points. Reading b is in sweep b mod sweeps.
  mapping::LinePitchConfig config;
  const std::size_t sweeps = static_cast<std::size_t>(sensors::InterlacedSweeps(
      scan.lines.empty() ? 0.0 : scan.lines.front().angle_increment_rad, config.sweep_step_rad));
  config.min_line_points = (config.min_line_points + sweeps - 1) / sweeps;
  std::vector<std::vector<std::uint32_t>> lines(scan.lines.size() * sweeps);
  for (std::size_t k = 0; k < scan.points.size(); ++k) {
    const std::size_t line = scan.points[k].line * sweeps + scan.points[k].beam % sweeps;
    if (line >= lines.size()) lines.resize(line + 1);
    lines[line].push_back(static_cast<std::uint32_t>(k));
  }
  std::vector<int> sweep_of(lines.size());
  for (std::size_t l = 0; l < lines.size(); ++l) sweep_of[l] = static_cast<int>(l % sweeps);
  mapping::LinePitch done = mapping::RectifyLinePitch(points, mount.t_base_mount_m.cast<float>(),
                                                      lines, config, sweep_of);
  // Lines, not their sweeps: the lines with any sweep long enough to be set right.
  std::size_t whole = 0;
  for (std::size_t l = 0; l < lines.size(); l += sweeps) {
    bool any = false;
    for (std::size_t s = 0; s < sweeps && l + s < lines.size(); ++s)
      any = any || lines[l + s].size() >= config.min_line_points;
    whole += any;
  }
  done.lines = whole;
  done.sweeps_per_line = static_cast<int>(sweeps);
  for (std::size_t k = 0; k < scan.points.size(); ++k) {
    scan.points[k].x = points[k].x();
    scan.points[k].y = points[k].y();
    scan.points[k].z = points[k].z();
  }
  return done;
}

mapping::ElevationMap ViewOver(const mapping::GridGeometry& area,
                               const std::vector<Eigen::Vector3f>& points,
                               const Eigen::Vector3f& laser) {
  Eigen::Vector2f lo = laser.head<2>(), hi = laser.head<2>();
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const mapping::CellIndex a = area.IndexOf(lo.x(), lo.y()), b = area.IndexOf(hi.x(), hi.y());
  const int i0 = std::clamp(a.i, 0, area.size_x - 1), j0 = std::clamp(a.j, 0, area.size_y - 1);
  const int i1 = std::clamp(b.i, 0, area.size_x - 1), j1 = std::clamp(b.j, 0, area.size_y - 1);
  mapping::GridGeometry local = area;
  local.x_min_m = area.x_min_m + i0 * area.cell_m;
  local.y_min_m = area.y_min_m + j0 * area.cell_m;
  local.size_x = i1 - i0 + 1;
  local.size_y = j1 - j0 + 1;
  mapping::ElevationMap view(local);
  view.InsertScan(points.data(), points.size(), laser);
  return view;
}

}  // namespace pitchlab::mission
