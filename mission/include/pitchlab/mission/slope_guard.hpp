#pragma once
// Driving on slopes with a top-heavy P3: the laser sits 0.45 m up, so the loaded P3-AT pitches
// over forward at about 31 deg standing (centre of mass 0.22 m high), less braking downhill or
// over a rock. The mission slows where the planned path is steep and
// backs off when its own tilt passes a caution limit; these helpers are the geometry of that.

#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// The grades of a path: its arc lengths computed once, so a controller can ask every step.
class PathGrade {
 public:
  /// Grades are measured over baselines of baseline_m along the path (single cells are too noisy
  /// to tell a slope). Keeps a reference to `path`.
  explicit PathGrade(const planning::Path& path, double baseline_m = 0.3);
  /// The steepest grade |dz| / ds between arc lengths from_m and to_m [m] [1].
  double Max(double from_m, double to_m) const;
  /// The steepest plane tilt `grid` gives the cells of the waypoints between arc lengths from_m
  /// and to_m [m] [rad]: across a slope the path is level and the robot still rolls by the
  /// slope's tilt. 0 where the map knows no tilt (and off the grid).
  double MaxTilt(const planning::TraversabilityGrid& grid, double from_m, double to_m) const;

 private:
  const planning::Path& path_;
  double baseline_m_;
  std::vector<double> arc_m_;  // arc length at each waypoint
};

/// PathGrade(path, baseline_m).Max(from_m, to_m), for a single question.
double MaxGrade(const planning::Path& path, double from_m, double to_m, double baseline_m = 0.3);

/// Ground the robot's own tilt showed to be too steep: an attitude sensor measures the slope over
/// the whole footprint, which a sparse scan of a rim or a crack can miss.
struct FeltHazard {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();  ///< world frame [m]
  double heading_rad = 0;                              ///< the robot's heading when it tilted [rad]
  double tilt_rad = 0;                                 ///< the tilt it felt [rad]
  double z_m = 0;                                      ///< base_link height estimate there [m]
  double radius_m = 0.35;                              ///< about the robot's half length [m]
  /// Something the robot ran onto (a tilt the ground it planned over does not explain: a wall's
  /// foot, a desk leg, a crack's edge): the cells become a step, not a slope.
  bool obstacle = false;
};

/// Gives every cell within f.radius_m of f.centre_m the felt slope (along the heading), so the
/// planner's inclination limit forbids them; unobserved cells there become observed at f.z_m.
/// An obstacle makes them a step (a point 0.5 m above the cell's mean). Drop cells stay drops.
void MarkFelt(mapping::ElevationLayers& layers, const FeltHazard& f);

}  // namespace pitchlab::mission
