#pragma once
// The map check of real_eval: an elevation map of real scans at given poses, levelled as `pitchlab
// map` levels it, held to what a corridor's floor is (one plane) and to what the planner can do
// on it (how far along the seen floor a P3-AT gets from the first scan's place).

#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::benchmarks {

/// One scan for the map: its points in its own frame, where its sensor stood in that frame, and
/// its pose in the map frame.
struct PosedCloud {
  const mapping::PointCloud* points = nullptr;
  Eigen::Vector3f sensor = Eigen::Vector3f::Zero();
  Eigen::Isometry3d T_map_scan = Eigen::Isometry3d::Identity();
};

/// Builds the map (0.1 m cells, `pitchlab map`'s defaults: levelled by the first scan's floor,
/// 1 m height band) and reports as JSON: the levelling; the floor (cells within the P3-AT's step
/// of the level floor under the first sensor): cells, the tilt of their least-squares plane, the
/// RMS residual about it and the share within +-2 cm; the seen floor's extent along the line from
/// the first scan's sensor to the last's; and, for each unknown policy, how far along that line
/// the floor cells reachable from the first sensor's cell extend. Throws std::runtime_error when the
/// floor cannot be levelled.
nlohmann::json CheckMap(const std::vector<PosedCloud>& scans);

}  // namespace pitchlab::benchmarks
