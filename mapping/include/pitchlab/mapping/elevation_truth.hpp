#pragma once
// Ground truth for elevation maps: the true surface under every cell from rays cast straight down
// through the world (any sensors::RayCaster, Embree in practice), and an estimate's error against
// it.

#include <cstddef>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"

namespace pitchlab::sensors {
class RayCaster;
}

namespace pitchlab::mapping {

/// How the true map is sampled.
struct TruthConfig {
  int samples_per_side = 3;  ///< k x k vertical rays per cell, on a regular sub-grid [1]
  double ray_top_z_m = 200;  ///< rays start at this height (above everything) [m]
  double max_depth_m = 400;  ///< and go down this far at most [m]
  /// Free height under an overhang for the floor beneath to count instead [m]: the P3 with its
  /// LMS200 on the default mount is ~0.6 m tall (mirror 0.54 m above base_link), so under a
  /// higher canopy, table or balcony the robot and its laser see (and drive on) the floor.
  /// 0 disables: the first surface from above counts, whatever is below it.
  double min_headroom_m = 0.6;
  int max_overhangs = 3;  ///< overhang layers looked through per vertical line [1]
};

/// The true elevation map over `geometry`: for each of the k x k vertical lines per cell, the
/// surface a ground robot stands on is inserted as a point, so the truth has the same layers
/// (mean, min, max, roughness, inclination) as an estimate. Cells where no ray hits (off the
/// world) stay unknown.
///
/// Which surface (rays only, no scene knowledge): the first hit from above, unless it is an
/// overhang, i.e. along the line (1) the next hit below is the same geom again (its underside:
/// a closed solid in mid-air, nothing else inside it), (2) no other geom's face touches that
/// underside (two short probes up and down; a face on a face, like a building on its slab or a
/// car cabin on its chassis, is one solid), (3) the next surface below is at least
/// `min_headroom_m` lower, and (4) that surface is a top: below it the ray meets the same geom
/// again (its bottom), or nothing and it is one-sided (a plane: a ray from just under it does
/// not see it). Then that floor counts, and is tested the same way
/// (up to `max_overhangs` layers). A tree's crown over open ground is an overhang; the line
/// through its trunk is not (the trunk is inside the crown), nor is a solid building.
ElevationMap ComputeTrueElevationMap(const sensors::RayCaster& caster, const GridGeometry& geometry,
                                     const TruthConfig& config = {});

/// An estimate's error against the truth, over cells known in both.
struct MapErrorReport {
  std::size_t compared_cells = 0;  ///< observed in both [1]
  std::size_t truth_cells = 0;     ///< known in the truth [1]
  double coverage = 0;             ///< compared / truth cells [0-1]
  double rmse_m = 0;               ///< of mean height [m]
  double mean_error_m = 0;         ///< estimate - truth, averaged (bias) [m]
  double max_abs_error_m = 0;      ///< [m]
  double p95_abs_error_m = 0;      ///< 95th percentile of |error| [m]
  std::size_t drop_cells = 0;      ///< estimate cells marked drop [1]
};

/// Compares mean heights cell by cell. Throws std::invalid_argument when the geometries differ.
MapErrorReport CompareToTruth(const ElevationLayers& estimate, const ElevationLayers& truth);

}  // namespace pitchlab::mapping
