#pragma once
// What one registered stop puts into the elevation map the robot plans on, in its own base_link:
// the scan's returns within the map range, where its laser sits, and the ground under the robot.
// The mission inserts it at the stop's pose; with loop closure it keeps it per scan
// (mapping::PerScanElevationMap) so the map follows the optimised poses, and a program that
// rebuilds that map from a run's stops uses the same inputs. A stop that did not register adds
// its view at the odometry pose to the cells the map has not seen (ViewOver).

#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/sensors/grazing_returns.hpp"
#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::mission {

/// A stop's scan as the elevation map takes it, base_link [m].
struct ElevationScan {
  std::vector<Eigen::Vector3f> points_base;  ///< returns within the map range, none grazed
  /// Returns within the map range left out as grazed (sensors/grazing_returns.hpp): on a steep
  /// surface, so obliquely that the footprint spreads over more than a map cell along the beam.
  std::size_t grazed = 0;
  Eigen::Vector3f sensor_base = Eigen::Vector3f::Zero();  ///< the laser, mirror at zero pitch
  /// The ground the robot stands on: the laser cannot see under the robot, but a registered pose
  /// knows that ground's height (a 0.4 m square at 0.1 m spacing, base_link's z = 0).
  std::vector<Eigen::Vector3f> ground_base;
};

/// The returns of `scan` no farther than `map_range_m` from the laser (MissionConfig's
/// map_range_m) except the grazed ones (a beam of `beam_divergence_rad` spreading over more than
/// `cell_m`, the map's cell, on a steep surface), the laser's place from `mount`, the footprint's
/// ground.
ElevationScan ElevationScanOf(const sensors::Scan3D& scan, double map_range_m,
                              const sensors::MountConfig& mount, double beam_divergence_rad,
                              double cell_m);

/// Sets each of `scan`'s lines right by the floor it crossed (mapping::RectifyLinePitch with the
/// scan's own lines, turned about the pitch axis through `mount`'s origin); ranges stay as they
/// are (the laser turns with its line). What was done is returned.
mapping::LinePitch SetLinesRight(sensors::Scan3D& scan, const sensors::MountConfig& mount);

/// `points` (world frame [m], rays from `laser`) inserted alone into a grid over their extent,
/// aligned to `area`'s cells: the view of a stop that did not register, which fills only the
/// cells the map has not seen (ElevationMap::Merge with MergeCells::kUnknown).
mapping::ElevationMap ViewOver(const mapping::GridGeometry& area,
                               const std::vector<Eigen::Vector3f>& points,
                               const Eigen::Vector3f& laser);

}  // namespace pitchlab::mission
