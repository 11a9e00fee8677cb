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
};

/// The true elevation map over `geometry`: every downward ray's first hit is inserted as a point,
/// so the truth has the same layers (mean, min, max, roughness, inclination) as an estimate.
/// Cells where no ray hits (off the world) stay unknown. The first surface from above counts
/// (a desk top, not the floor beneath it: what a robot's laser sees from the side may differ).
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
