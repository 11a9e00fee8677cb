#pragma once
// The map pictures of a run folder, each cropped to the explored area with axes in metres, a
// scale bar and start/goal markers (map_figure.hpp): the same crop for the estimated and the true
// map, so the two can be compared side by side.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mission.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "run_folder.hpp"
#include "run_outputs.hpp"

namespace pitchlab::apps {

/// The estimated (or, with `truth`, the true) x, y of every trajectory sample [m].
std::vector<Eigen::Vector2d> TrajectoryXy(const MissionResult& result, bool truth);

/// Writes elevation.png (estimated map, every plan in red, estimated trajectory orange, true
/// blue, colour bar), traversability.png and, with `truth`: truth_elevation.png (true optimal
/// path red, true trajectory blue), truth_traversability.png and hazard_errors.png. Throws
/// std::runtime_error naming the file on a write failure.
void WriteRunPictures(RunFolder& folder, const RunContext& context, const MissionResult& result,
                      const mapping::ElevationLayers& layers, const mapping::ElevationLayers* truth,
                      const std::optional<planning::Path>& truth_optimum);

/// A stop's map.png: the map so far with the stop's plan, cropped to what is known, the start
/// (the first trajectory sample) and the plan's goal marked.
mapping::RgbImage StopPicture(const MissionResult& so_far,
                              const std::optional<planning::Path>& plan);

}  // namespace pitchlab::apps
