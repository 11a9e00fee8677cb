#pragma once
// The bridge to ROS navigation stacks: a map_server occupancy grid (a PGM image and its YAML),
// read as a cost map the planner searches, and the traversability written as one.
//
// Format (ROS map_server, ROS 1 wiki and Nav2 map_server): YAML keys image (relative to the
// YAML's folder, or absolute), resolution [m/pixel], origin [x, y, yaw] (the lower-left pixel's
// outer corner), negate, occupied_thresh, free_thresh, optional mode (trinary, the default; scale;
// raw). A pixel x of an image of maxval M reads as p = (M - x) / M (x / M with negate), then
//   trinary: p > occupied_thresh -> 100 (occupied), p < free_thresh -> 0 (free), else -1 (unknown)
//   scale:   the same ends, in between 99 (p - free) / (occupied - free), rounded (a PGM has no
//            alpha channel: no unknown)
//   raw:     the value is x itself, 0..100; above 100 unknown (Nav2; ROS 1's int8 makes 255 -1)
// pitchlab writes raw (0 free, 1..99 the cost as grey levels, 100 lethal, 255 unknown): the only
// mode in which a PGM carries free, lethal, unknown and costs at once.

#include <cstdint>
#include <string>
#include <vector>

#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::planning {

/// An occupancy grid in the map_server frame: row 0 the southern (the YAML origin's) row.
struct OccupancyGrid {
  mapping::GridGeometry geometry;  ///< x_min/y_min the origin, cell_m the resolution
  std::vector<std::int8_t> value;  ///< per cell (GridGeometry::Linear): -1 unknown, 0..100 [%]
};

inline constexpr std::int8_t kOccupancyUnknown = -1;
inline constexpr std::int8_t kOccupancyLethal = 100;

/// Reads a map_server YAML and its image (PGM, P5 or P2, maxval up to 65535). Fails
/// (kInvalidArgument; kNotFound when a file cannot be opened) with "FILE:LINE: what is wrong": a
/// missing, repeated or unknown key, a bad value (resolution <= 0, thresholds outside
/// 0 <= free < occupied <= 1, an origin yaw other than 0: the grid would be rotated, which
/// pitchlab's maps are not), an image that is not PGM or ends early.
[[nodiscard]] Result<OccupancyGrid> LoadOccupancyGrid(const std::string& yaml_path);

/// Eq. 5's entry cost (W_T*T + W_phix*|phi_x| + W_phiy*|phi_y|) of a cell at the robot's limits:
/// tilted to max_inclination along both axes, its heights spread like a step_max step through it
/// (T = step_max / 2). The cost that grey level 99 stands for [1].
double FullScaleCost(const PlannerConfig& config);

/// The traversability as occupancy: step, drop, too steep and occupied cells lethal (100);
/// unknown cells (and seen ones whose slope the scan did not determine, under kForbid) -1; every
/// other cell, the footprint's margin included (a navigation stack inflates lethal cells by its
/// own footprint), its entry cost as round(99 * cost / FullScaleCost), at most 99.
OccupancyGrid ToOccupancy(const TraversabilityGrid& grid);

/// Writes `grid` as a map_server map: `yaml_path` and a PGM of the same stem (raw mode, see the
/// top of this file). Both written atomically; errors name the file.
[[nodiscard]] Result<void> WriteOccupancyGrid(const OccupancyGrid& grid,
                                              const std::string& yaml_path);

/// The planning graph of an occupancy grid: 100 (occupied) cells are obstacles
/// (Blocked::kOccupied, inflated by the footprint as steps are); -1 cells unknown (the config's
/// policy); a cell of value v in 0..99 free, entered at v / 99 * FullScaleCost(config) plus
/// Eq. 4's length (no heights: P is the flat distance). Throws std::invalid_argument on a bad
/// config.
TraversabilityGrid BuildTraversability(const OccupancyGrid& grid, const PlannerConfig& config);

}  // namespace pitchlab::planning
