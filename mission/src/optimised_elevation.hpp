#pragma once
// The elevation map the robot plans on when loop closure is on (issue 20): the registered stops'
// scans kept one by one (mapping::PerScanElevationMap) at the pose graph's latest poses, so after
// an optimisation that moved poses the map is the one built from scratch at the optimised poses.
// Scans that failed to register entered at odometry poses; they fill only the cells no registered
// scan saw (in stop order), on top: an odometry pose is not a graph node, nothing re-poses it.

#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/per_scan_elevation_map.hpp"
#include "pitchlab/mission/elevation_scan.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mission {

class OptimisedElevation {
 public:
  /// An all-unknown map over `area` (world frame). Throws std::invalid_argument when empty.
  explicit OptimisedElevation(const mapping::GridGeometry& area) : scans_(area) {}

  /// A registered stop's scan, `id` its MapBuilder scan index, at T_world_base. Errors: the id
  /// already present, a non-rigid pose.
  [[nodiscard]] Result<void> Insert(std::size_t id, const ElevationScan& scan,
                                    const Eigen::Isometry3d& T_world_base) {
    return scans_.Insert(id, scan.points_base, scan.sensor_base, T_world_base, scan.ground_base);
  }
  /// Moves registered scans to new poses (id, T_world_base); returns how many moved. Errors: an
  /// unknown id, a non-rigid pose (nothing moved then).
  [[nodiscard]] Result<std::size_t> Repose(
      const std::vector<std::pair<std::size_t, Eigen::Isometry3d>>& T_world_base) {
    return scans_.Repose(T_world_base);
  }
  /// An odometry-pose view (ViewOver), in stop order: it fills the cells still unknown.
  void AddOdometryView(mapping::ElevationMap view) { views_.push_back(std::move(view)); }
  /// The combined map: the registered scans, then each view's cells where none is known.
  mapping::ElevationMap Map() const;

 private:
  mapping::PerScanElevationMap scans_;
  std::vector<mapping::ElevationMap> views_;
};

}  // namespace pitchlab::mission
