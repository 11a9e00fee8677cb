#include "drive_length.hpp"

#include <algorithm>
#include <cmath>

namespace pitchlab::mission {

KnownStretch PlanKnownStretch(const planning::Path& path, const planning::TraversabilityGrid& grid) {
  KnownStretch known;
  known.to_the_end = path.waypoints.size() <= 1;
  const mapping::GridGeometry& g = grid.geometry;
  for (std::size_t i = 1; i < path.waypoints.size(); ++i) {
    const planning::Waypoint &v = path.waypoints[i - 1], &w = path.waypoints[i];
    const std::size_t k = g.Linear(g.IndexOf(w.x_m, w.y_m));
    if (!std::isfinite(grid.z_m[k]) || grid.line_gap[k]) break;
    known.length_m += std::hypot(w.x_m - v.x_m, w.y_m - v.y_m);
    known.to_the_end = i + 1 == path.waypoints.size();
  }
  return known;
}

double PlanClearStretch(const planning::Path& path, const planning::TraversabilityGrid& grid,
                        double error_per_m, double up_to_m) {
  const mapping::GridGeometry& g = grid.geometry;
  const double reach_m = planning::FootprintReach(grid);
  double arc_m = 0, drift_m = 0;
  for (std::size_t i = 0; i < path.waypoints.size(); ++i) {
    const planning::Waypoint& w = path.waypoints[i];
    const mapping::CellIndex c = g.IndexOf(w.x_m, w.y_m);
    if (i > 0) {
      const planning::Waypoint& v = path.waypoints[i - 1];
      const double step_m = std::hypot(w.x_m - v.x_m, w.y_m - v.y_m);
      arc_m += step_m;
      if (g.Contains(c) && grid.Tilt(g.Linear(c)) > kFloorTilt_rad) {
        drift_m += error_per_m * step_m;
      }
    }
    if (arc_m >= up_to_m) return arc_m;
    const double keep_m = reach_m + drift_m;
    const int r = static_cast<int>(std::ceil(keep_m / g.cell_m));
    for (int dj = -r; dj <= r; ++dj)
      for (int di = -r; di <= r; ++di) {
        const mapping::CellIndex nb{c.i + di, c.j + dj};
        if (!g.Contains(nb) || !planning::IsFootprintHazard(grid.blocked[g.Linear(nb)])) continue;
        const Eigen::Vector2d d = g.CenterOf(nb) - Eigen::Vector2d(w.x_m, w.y_m);
        if (d.norm() < keep_m) return arc_m;
      }
  }
  return arc_m;
}

DriveLength PlanDriveLength(double drive_per_stop_m, double unknown_margin_m, double plan_known_m,
                            bool seen_to_the_end, bool last_turned_only,
                            std::optional<double> plan_to_doubt_m) {
  DriveLength drive;
  drive.length_m = std::min(drive_per_stop_m, seen_to_the_end ? plan_known_m
                                                              : plan_known_m - unknown_margin_m);
  if (seen_to_the_end && !plan_to_doubt_m) return drive;
  drive.turn_only = drive.length_m < unknown_margin_m && !last_turned_only;
  if (drive.turn_only) return drive;
  if (last_turned_only) drive.length_m = std::max(drive.length_m, std::min(drive_per_stop_m, 1.0));
  if (plan_to_doubt_m) drive.length_m = std::min(drive.length_m, *plan_to_doubt_m - unknown_margin_m);
  return drive;
}

double CutForDrift(double length_m, double plan_clear_m) {
  if (plan_clear_m >= length_m) return length_m;
  return std::max(std::min(length_m, kMinDriftCut_m), plan_clear_m);
}

double MinDriveLength(const PurePursuitConfig& follower) {
  constexpr double kMinDrive_m = 0.1;  // a drive shorter than this is no progress
  return std::max(kMinDrive_m, follower.goal_tolerance_m);
}

}  // namespace pitchlab::mission
