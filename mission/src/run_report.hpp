#pragma once
// report.html of a run: the outcome and its reason first, the metrics that matter with units,
// then the 3D view, the map pictures, the trajectories, the stops, links to the run's files, and
// everything else folded at the end.

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "html_report.hpp"
#include "pitchlab/mission/mission.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "report_viewer.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/run_outputs.hpp"

namespace pitchlab::mission {

/// A picture of the run folder shown in the report.
struct ReportPicture {
  std::string file;     ///< relative to the run folder
  std::string caption;  ///< under the picture
  std::string legend;   ///< a sentence before it (may be empty)
  std::string full = "";  ///< the full-size picture a thumbnail opens (empty: `file` itself)
};

/// Everything report.html shows, gathered from a run (GatherRunReport) or made by a test.
struct RunReportInput {
  nlohmann::json metrics;  ///< RunMetrics' JSON
  std::string config_yaml;
  std::filesystem::path folder;  ///< where the pictures are read from
  std::vector<ReportPicture> pictures;
  std::vector<PlotSeries> trajectories;
  std::vector<PlotMarker> markers;
  std::vector<std::string> stop_header;
  std::vector<std::vector<std::string>> stop_rows;
  std::vector<ReportPicture> stop_pictures;  ///< thumbnails, each with its `full` picture
  std::string scene_json;                    ///< SceneJson(); empty: no 3D view
  std::vector<std::string> files;            ///< the run folder's files, relative paths
};

/// The page. `three` is three.js (LoadThreeJs) or why it is missing: then the page says the 3D
/// view is unavailable and why. Throws std::runtime_error naming a picture file it cannot read.
std::string RenderRunReport(const RunReportInput& input, const Result<ThreeJs>& three);

/// Collects the report's input from a run whose other files are already in `folder`.
RunReportInput GatherRunReport(const RunFolder& folder, const RunContext& context,
                               const MissionResult& result, const nlohmann::json& metrics,
                               const FinalMap& final_map);

/// Writes report.html (three.js from DefaultThreeJsDir; when it is missing the page says so and
/// a warning goes to stderr). Throws std::runtime_error naming the file on a write failure.
void WriteRunReport(RunFolder& folder, const RunContext& context, const MissionResult& result,
                    const nlohmann::json& metrics, const FinalMap& final_map);

}  // namespace pitchlab::mission
