#pragma once
// The layers users and the planner read, derived from an ElevationMap's running statistics:
// mean height (Eq. 2), roughness T (Eq. 3), inclination phi_x, phi_y, and what is known.
//
// Inclination: a least-squares plane z = a + b x + c y through the points of the cell and its
// neighbours (the 3 x 3 cell region by default, LayerConfig::inclination_radius_cells), computed
// from the cells' co-moments (no point is re-read) with each cell counted once (its points'
// spread scaled to one point's worth): the ground's slope, not where the scanner put its points
// (pooled by point, a dense flat patch outweighed a mound's sparsely seen flank: 25-37 deg read
// as 5-15, and robots tipped over there). phi_x = atan(b), phi_y = atan(c). Whether the scan
// determined a slope at all is judged on the points pooled. When they do not span the plane (fewer than 3, or
// all on one line, e.g. a single scan line), the same fit is made through the centres of the known
// cells of the region at their mean heights; with fewer than 3 non-collinear known cells the
// inclination is unknown (NaN). A neighbour whose mean differs from the cell's by more than
// max_fit_slope times their centre distance is a step, not part of the slope, and is left out, so
// the ground beside a wall keeps its own inclination. A fit the scan does not support (its slope's
// standard error above LayerConfig::max_slope_error) leaves the inclination unknown.

#include <cstdint>
#include <vector>

#include "pitchlab/mapping/elevation_map.hpp"

namespace pitchlab::mapping {

/// What is known of a cell.
enum class CellState : std::uint8_t {
  kUnknown = 0,   ///< no point fell in it and no ray proves a drop
  kObserved = 1,  ///< at least one point
  kDrop = 2,      ///< no point, but rays passed lower than the lowest point of every observed
                  ///< neighbour by more than drop_depth_m, one of them a rim (ground with a
                  ///< supported inclination whose points span less than drop_depth_m: not a
                  ///< few points of a wall), or within drop_flood_m of such a drop
              ///< cell, below the same reference): a negative hazard (ditch, stairs down, cliff)
};

/// How the derived layers are made.
struct LayerConfig {
  /// The inclination's fit region: the (2r + 1) x (2r + 1) cells around a cell. 1 (3 x 3) follows
  /// the ground closely; a robot tips over with the slope under its whole footprint, so a planner
  /// for a 0.5 m robot on 0.1 m cells reads it better with 2 (5 x 5), where rocks and cracks
  /// still show as steps and roughness.
  int inclination_radius_cells = 1;
  double drop_depth_m = 0.2;  ///< clearance this far below an observed neighbour is a drop [m]
  /// How far a drop grows from the cells next to observed ground, through unknown cells whose
  /// rays pass below the same reference [m]. The rim is the hazard; an unbounded flood spread a
  /// reference taken from something tall (a fence seen only above a ray) over whole streets.
  double drop_flood_m = 1.0;
  /// A region whose point spread is smaller than this along its narrow horizontal axis is
  /// degenerate for the point fit (its sqrt of the smallest eigenvalue of the xy covariance) [m].
  double min_spread_m = 0.005;
  /// Neighbours steeper than this from the cell (|dz| / centre distance) are steps, excluded
  /// from the inclination fit [1]; tan(60 deg).
  double max_fit_slope = 1.7320508;
  /// Support of the inclination: a fit counts only when its slope's standard error, for heights
  /// of `height_noise_m`, is at most `max_slope_error`; else the inclination is unknown (NaN) and
  /// the cell is no slope hazard. What the scan supports follows from the sensor: the LMS200's
  /// 0.5 deg beams lie r * 8.7 mm apart along a line, and a nodding scan's lines (0.45 deg pitch
  /// steps) meet a floor h = 0.5 m below the laser r^2 * 0.0079 / h apart: 0.14 m at 3 m, 0.57 m
  /// at 6 m. Beyond ~4.5 m a 3 x 3 region of 0.1 m cells holds one line, whose points span no
  /// plane across it (a single line's noise set the far floor's "slopes": one-cell steep stripes
  /// across office corridors and a real corridor). 3 x 3 full cells of one point each: error
  /// 0.02 / sqrt(6 * 0.01) = 0.08, supported; two rows of them: 0.16, not.
  /// Height noise of one point [m]: real LMS scans 1-3 cm (the 3DTK corridor's floor fits a
  /// plane to 2 cm RMS), more than the datasheet's 5 mm range noise because the pose's and
  /// the pitch encoder's angle errors grow with range.
  double height_noise_m = 0.02;
  /// [1] A third of the P3-AT's 35 % grade: flat ground reads as too steep by chance less than
  /// a 3-sigma event.
  double max_slope_error = 0.35 / 3;
};

/// Where a cell's points lie about its centre, along x and along y [m].
struct PointSpan {
  float lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
};

/// Dense per-cell layers over the map's geometry (index as GridGeometry::Linear).
struct ElevationLayers {
  GridGeometry geometry;
  std::vector<CellState> state;
  std::vector<std::uint32_t> count;  ///< points [1]
  std::vector<float> mean_z;         ///< Eq. 2 cell elevation [m]; NaN unknown
  std::vector<float> min_z;          ///< [m]; NaN unknown
  std::vector<float> max_z;          ///< [m]; NaN unknown
  /// The second lowest and second highest point [m] (CellStats): NaN unknown, +-inf with one
  /// point. Layers built by hand may leave them empty: the extremes then stand for them.
  std::vector<float> next_min_z;
  std::vector<float> next_max_z;
  std::vector<float> roughness;      ///< Eq. 3 T: std dev of the cell's heights [m]; NaN unknown
  std::vector<float> phi_x;          ///< inclination along x: atan(dz/dx) [rad]; NaN unknown
  std::vector<float> phi_y;          ///< inclination along y: atan(dz/dy) [rad]; NaN unknown
  std::vector<float> clearance_z;    ///< lowest ray height over the cell [m]; +inf none
  /// RMS vertical distance of the cell's own points from their least-squares plane [m]; NaN with
  /// fewer than 4 points or points that do not span a plane (a single scan line). Ground of any
  /// slope leaves the range noise here; a step inside the cell (a curb on the cell's edge, both
  /// sides seen) leaves about a quarter of its height, which the mean heights alone smear into
  /// two half steps.
  std::vector<float> plane_residual;
  /// Where the cell's points lie about its centre: per axis their mean -/+ their standard
  /// deviation times min(sqrt(3), sqrt(n - 1)), within the cell. sqrt(3) sigma is the half range
  /// of points spread evenly; n points lie within sqrt(n - 1) sigma of their mean (Samuelson's
  /// inequality), so one point spans nothing and two exactly their distance. A gap in the ground
  /// is measured between the points that bound it, not between cell edges. All zero when unknown;
  /// may be empty (layers made by hand): every cell's points are then taken at its centre.
  std::vector<PointSpan> point_span;
  /// One point's height noise the layers were computed for (LayerConfig::height_noise_m) [m]: what
  /// a step between cells of few points must stand out of (planning's step support).
  double height_noise_m = 0.02;

  /// Overall tilt of the cell's plane, atan(sqrt(tan^2 phi_x + tan^2 phi_y)) [rad]; NaN unknown.
  float Tilt(std::size_t k) const;
};

/// Eq. 3: population standard deviation of the cell's heights [m]; NaN for an unknown cell.
float Roughness(const CellStats& cell);

/// Computes every layer. O(cells). Throws std::invalid_argument on a bad config.
ElevationLayers ComputeLayers(const ElevationMap& map, const LayerConfig& config = {});

/// The same into `layers`, reusing its buffers: a caller that derives the layers of one map at
/// every stop allocates them (and the kernel clears their pages) once, not every time.
void ComputeLayersInto(const ElevationMap& map, const LayerConfig& config, ElevationLayers& layers);

}  // namespace pitchlab::mapping
