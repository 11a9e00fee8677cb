#pragma once
// The steps every traversability grid ends with, whatever map it came from (elevation layers or
// an occupancy grid): the footprint's inflation, soft clearance, move masks and costs.

#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::planning {

/// Sets `grid` to `geometry` and `config` with every cell free, at no cost, of unknown height and
/// no roughness or inclination, and no occupancy costs: what each source of a grid starts from.
void StartTraversability(const mapping::GridGeometry& geometry, const PlannerConfig& config,
                         TraversabilityGrid& grid);

/// Given `blocked`, `enter_cost` and `z_m` per cell: blocks the footprint's margin around every
/// hazard and the grid's edge, adds the soft clearance, and fills moves, move_cost and the cost
/// range the searches need.
void FinishTraversability(TraversabilityGrid& grid);

}  // namespace pitchlab::planning
