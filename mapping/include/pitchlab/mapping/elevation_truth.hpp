#pragma once
// Ground truth for elevation maps: the true surface under every cell from rays cast straight down
// through the world (any sensors::RayCaster, Embree in practice), and an estimate's error against
// it.

#include <cstddef>
#include <functional>
#include <vector>

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
  /// Called after each row of cells with (rows done, rows) when set: the truth of a large world
  /// takes seconds, and a command says how far it is.
  std::function<void(int done, int rows)> progress;
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

/// The layers of a true elevation map (ComputeTrueElevationMap): ComputeLayers with `config`, but
/// its heights are exact, so they carry no point noise (`height_noise_m` 0) and no mixed pixel
/// (a cell's extremes stand for its second extremes): its steps are judged as measured, not as a
/// laser's few noisy points.
ElevationLayers ComputeTruthLayers(const ElevationMap& truth, const LayerConfig& config = {});

/// How an estimate is scored against the truth.
///
/// What the truth means at a wall. The truth of a cell is the surface a ground robot stands on
/// there, averaged over the cell (the k x k vertical lines). A vertical face (a building wall, a
/// car's side, the edge of a drop) has no such height: the roof is on one side, the ground on the
/// other, and the face itself is not a surface. The laser sees the face, and its points (range
/// noise and the 1 cm range unit move them by a centimetre or so, along the beam) land on both
/// sides of it; where the face lies on a cell edge, as every wall of a world built on a 0.1 m
/// raster does, the ground cell in front gets points metres up the wall and the roof cell behind
/// gets wall points instead of its unseen roof, so their Eq. 2 means are off by up to the wall's
/// height. Those cells are "wall cells": a cell whose 3 x 3 block of true cells spans more height
/// than a `wall_slope` face over the block's width (3 cells) could, i.e. a face steeper than that
/// runs through the cell or along its edge. Their height error says how much of the face the laser
/// saw, not how well the surface is mapped, so it is reported apart (wall_*) and kept out of the
/// surface figures (rmse_m, mean, max, p95); the planner treats them as the hazard they are either
/// way (a step to the neighbour, or a spread within the cell).
struct CompareConfig {
  /// Steepness of a vertical face [1]: tan(60 deg), the slope beyond which the layers treat a
  /// neighbour as a step (LayerConfig::max_fit_slope); <= 0 makes no cell a wall cell.
  double wall_slope = 1.7320508;
};

/// An estimate's error against the truth, over cells known (observed) in both.
struct MapErrorReport {
  std::size_t compared_cells = 0;  ///< observed in both, wall cells included [1]
  std::size_t truth_cells = 0;     ///< known in the truth [1]
  double coverage = 0;             ///< compared / truth cells [0-1]
  // The surface: compared cells that are not wall cells (see CompareConfig).
  std::size_t surface_cells = 0;  ///< [1]
  double rmse_m = 0;              ///< of mean height [m]
  double mean_error_m = 0;        ///< estimate - truth, averaged (bias) [m]
  double max_abs_error_m = 0;     ///< [m]
  double p95_abs_error_m = 0;     ///< 95th percentile of |error| [m]
  // Wall cells, and all compared cells together (the figure before walls were told apart).
  std::size_t wall_cells = 0;      ///< compared cells at a vertical face [1]
  double wall_rmse_m = 0;          ///< [m]
  double all_rmse_m = 0;           ///< over every compared cell [m]
  double all_max_abs_error_m = 0;  ///< [m]
  std::size_t drop_cells = 0;      ///< estimate cells marked drop [1]
};

/// Compares mean heights cell by cell. Throws std::invalid_argument when the geometries differ.
MapErrorReport CompareToTruth(const ElevationLayers& estimate, const ElevationLayers& truth,
                              const CompareConfig& config = {});

/// Wall cells of a true map (see CompareConfig), one flag per cell.
std::vector<bool> WallCells(const ElevationLayers& truth, const CompareConfig& config = {});

}  // namespace pitchlab::mapping
