#pragma once
// The data of the report's 3D view: the merged cloud (decimated), the elevation surface coloured
// by traversability, both trajectories and the stops, packed small enough to inline in the page
// (positions quantised to 16 bits, base64).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mission/map_figure.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// At most this many cloud points go into a page: 100k points are 0.8 MB of base64, and a
/// software-rendered WebGL canvas still orbits them smoothly.
inline constexpr std::size_t kSceneMaxPoints = 100000;
/// At most this many surface cells (a 400 x 400 window); larger windows are subsampled.
inline constexpr std::size_t kSceneMaxCells = 160000;

/// A heightfield over a window of the map: cell (i, j) at x0 + (i + 0.5) * cell.
struct SceneSurface {
  double x0_m = 0, y0_m = 0, cell_m = 0.1;
  int nx = 0, ny = 0;
  std::vector<float> z_m;         ///< nx * ny, index j * nx + i; NaN unknown
  std::vector<std::uint8_t> rgb;  ///< nx * ny * 3, RenderTraversability's colours
};

/// Everything the 3D view shows, in the world frame [m].
struct Scene3D {
  std::vector<Eigen::Vector3f> cloud_m;
  SceneSurface surface;
  std::vector<Eigen::Vector3d> true_m, estimated_m, stops_m;
  Eigen::Vector3d start_m{0, 0, 0}, goal_m{0, 0, 0};
};

/// Every k-th point, k the smallest that leaves at most `max_points` (the merged cloud is in scan
/// order, so this keeps each scan's share and its density pattern).
std::vector<Eigen::Vector3f> DecimateCloud(const mapping::PointCloud& cloud,
                                           std::size_t max_points);

/// The surface of `layers` over `window`, coloured by `grid` (built from the same layers); every
/// s-th cell in each direction with s the smallest that keeps at most kSceneMaxCells.
SceneSurface BuildSurface(const mapping::ElevationLayers& layers,
                          const planning::TraversabilityGrid& grid, const MapWindow& window);

/// The scene as the JSON object the viewer's script reads (format in report_scene.cpp).
std::string SceneJson(const Scene3D& scene);

}  // namespace pitchlab::mission
