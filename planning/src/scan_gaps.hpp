#pragma once
// Gaps between scan lines: ground the laser's rays passed over, close above, without a return.

#include <cstddef>

#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::planning {

/// Marks as ground the unknown cells of `grid` that lie in a gap between scan lines: a run of
/// unknown cells along x or y, no wider than the robot's wheels roll over (MaxBridgedGap), with
/// ground on both ends (observed, free, a supported inclination) no more than a step apart, and
/// every cell of it crossed by a ray no higher than a step above the line between those ends, so
/// nothing the robot could not drive over stands there. A nodding laser leaves such gaps where
/// its lines meet the floor sparsely or its sweep has a hole (the real 3DTK corridor: a one- to
/// two-cell stripe right across the floor 1.3 m ahead); a hole in them narrower than the wheel
/// sinks the wheel less than a step. Each cell takes the height on that line, the rougher end's
/// roughness and the ends' mean inclination. Grids coarser than the robot get nothing: their
/// cells are wider than any gap a wheel spans. Returns how many cells it marked.
std::size_t BridgeScanGaps(const mapping::ElevationLayers& layers, TraversabilityGrid& grid);

}  // namespace pitchlab::planning
