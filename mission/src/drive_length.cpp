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

double MinDriveLength(const PurePursuitConfig& follower) {
  constexpr double kMinDrive_m = 0.1;  // a drive shorter than this is no progress
  return std::max(kMinDrive_m, follower.goal_tolerance_m);
}

}  // namespace pitchlab::mission
