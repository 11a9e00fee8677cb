#pragma once
// Where registration failed, a scan enters the elevation map at the odometry pose, whose height
// drifts (terrain: 0.55 m p95 between stops, from pitch integrated over slopes and slip): placed as
// is, the scan's ground stands above or below the map's and reads as steps all around the robot.
// Its height is taken from the ground the map already holds instead: how far the scan's ground
// lies above the map's, cell by cell where both saw it. Only the height: the attitude sensor's
// roll and pitch (0.2 deg) are better than a tilt fitted here, where odometry's horizontal error
// on sloped ground looks like a tilt (fitting one made 0.2 deg errors 3-8 deg in terrain runs).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_map.hpp"

namespace pitchlab::mission {

/// How far a scan's ground lies above the map's.
struct HeightOffset {
  double dz_m = 0;  ///< [m]
  int cells = 0;    ///< cells the estimate used [1]
};

/// The offset of `points` (world frame) against the cells of `map` that hold at least 3 points,
/// comparing per-cell means where the scan has 3 points or more too and neither's points rise
/// more than a 60 deg face across the cell (ground, not a wall's face): the mean difference over
/// the cells within 3 scaled MADs (at least 5 cm) of the median, which drops what changed or was
/// seen from another side (a wall's top, a rock's flank). nullopt below `min_cells` cells.
std::optional<HeightOffset> FitHeightOffset(const mapping::ElevationMap& map,
                                            const std::vector<Eigen::Vector3f>& points,
                                            int min_cells = 50);

}  // namespace pitchlab::mission
