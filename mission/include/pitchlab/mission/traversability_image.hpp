#pragma once
// A picture of what the planner may enter: which cells are free and why the others are not. It
// is how a user sees why a run routed the way it did, or found no path.

#include <string>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// Free cells in shades of green (darker costs more to enter), unknown cells as the elevation
/// picture's checkerboard, steps red, too steep orange, drops magenta, cells within the robot's
/// half width of a hazard pale red. North up, the same pixel grid as RenderElevationImage with
/// the same options.
mapping::RgbImage RenderTraversability(const planning::TraversabilityGrid& grid,
                                       const mapping::ImageOptions& options = {});

/// The legend of RenderTraversability's colours, one sentence.
std::string TraversabilityLegend();

/// Where the map's hazards are wrong (CompareHazard): false hazards red (pink where the truth's
/// free cell is out of reach from `start_m`, world [m]: planning::ReachableCells), missed hazards blue,
/// agreeing cells grey (darker where both see a hazard), cells not compared checkered. Same pixel
/// grid as RenderTraversability.
mapping::RgbImage RenderHazardErrors(const planning::TraversabilityGrid& estimated,
                                     const planning::TraversabilityGrid& truth,
                                     const Eigen::Vector2d& start_m,
                                     const mapping::ImageOptions& options = {});

/// The legend of RenderHazardErrors' colours, one sentence.
std::string HazardErrorsLegend();

}  // namespace pitchlab::mission
