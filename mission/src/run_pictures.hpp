#pragma once
// The map pictures of a run folder, each cropped to the explored area with axes in metres, a
// scale bar and start/goal markers (map_figure.hpp): the same crop for the estimated and the true
// map, so the two can be compared side by side.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mission/mission.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/run_outputs.hpp"

namespace pitchlab::mission {

/// The estimated (or, with `truth`, the true) x, y of every trajectory sample [m].
std::vector<Eigen::Vector2d> TrajectoryXy(const MissionResult& result, bool truth);

/// Writes elevation.png (estimated map, every plan in red, estimated trajectory orange, true
/// blue, colour bar), traversability.png (the grid the mission planned on) and, with `truth`:
/// truth_elevation.png (true optimal path red, true trajectory blue), truth_traversability.png
/// (the true grid the optimum and the score were found on, the true trajectory blue, ringed where
/// it crossed forbidden cells: TruthMaps::forbidden_crossed_at) and hazard_errors.png (the cells
/// ScoreRun counted, from the very grids it compared). A failed run
/// also gets last_plan.png: the traversability its last plan was made on (the mission's own grid,
/// MissionResult::last_plan_grid), that plan in red, and the run's tracks (estimated orange, true
/// blue). Throws std::runtime_error naming the file on a write failure.
void WriteRunPictures(RunFolder& folder, const RunContext& context, const MissionResult& result,
                      const FinalMap& final_map, const TruthMaps* truth);

/// What a stop's picture needs of the run so far, and no more: the part of the map it shows with
/// what the layers there read (a few percent of a large map's cells: a copy the thread beside the
/// mission can draw from while the mission goes on), the whole map's grid (it sets the picture's
/// scale), the estimated trajectory and the stop's plan.
struct StopView {
  mapping::ElevationMap region;
  mapping::GridGeometry whole;
  std::vector<Eigen::Vector2d> trajectory_m;  ///< estimated x, y of every sample [m]
  std::optional<planning::Path> plan;
};
StopView ViewOfStop(const MissionResult& so_far, const std::optional<planning::Path>& plan);

/// A stop's map.png: the map so far with the stop's plan, cropped to what is known, the start
/// (the first trajectory sample) and the plan's goal marked. The same pixels as the whole map's.
mapping::RgbImage StopPicture(const StopView& view);

/// The report's thumbnails are this wide [px]: twice the 240 px they are shown at, sharp on a
/// high-density screen. Measured on the default terrain run: 66 KB a thumbnail, so the default
/// run.max_stops (40) puts ~3.5 MB of base64 into a page that must stay under 10 MB.
inline constexpr int kThumbnailWidth_px = 480;

/// `image` shrunk by a whole factor to at most `max_width_px` wide, each pixel the mean of the
/// block it replaces.
mapping::RgbImage Downscale(const mapping::RgbImage& image, int max_width_px);

/// Writes `dir`map.png (StopPicture) and `dir`map_small.png (its thumbnail). Throws
/// std::runtime_error naming the file on a write failure.
void WriteStopPictures(RunFolder& folder, const std::string& dir, const StopView& view);

/// WriteStopOutputs (run_outputs.hpp) with the stop's picture drawn from `view`, for a caller that
/// writes them on another thread while the mission goes on.
void WriteStopOutputs(RunFolder& folder, const StopRecord& stop, const StopView& view,
                      const std::optional<mapping::GeodeticOrigin>& origin,
                      const std::string& world);

}  // namespace pitchlab::mission
