#pragma once
// Worlds are MJCF files without a robot. Composition splices the generated robot into a copy of
// the world's text (never writing the world folder) and makes its relative asset paths absolute.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "pitchlab/sim/robot_model.hpp"

namespace pitchlab::sim {

/// The pitchlab custom fields of a world (`<custom><numeric|text name="pitchlab:...">`).
struct WorldInfo {
  std::string path;                                ///< world file, or "<string>" for inline worlds
  std::string description;                         ///< text pitchlab:description, empty when absent
  std::optional<Eigen::Vector3d> geodetic_origin;  ///< pitchlab:geodetic_origin (lat, lon, h)
  std::optional<Eigen::Vector4d> bounds;           ///< pitchlab:bounds xmin ymin xmax ymax [m]
  std::optional<Eigen::Vector3d> default_start;  ///< pitchlab:default_start x [m], y [m], yaw [rad]
};

/// Returns the world's MJCF with the robot spliced in: body at the end of <worldbody>, its
/// defaults/actuators/sensors as extra top-level sections, relative file="..." attributes and
/// compiler meshdir/texturedir made absolute against `world_dir`. Throws std::runtime_error naming
/// `source_name` when the text has no <mujoco> root or no <worldbody>, or already has a "robot".
std::string ComposeWorldXml(const std::string& world_xml, const std::string& world_dir,
                            const RobotConfig& robot, const std::string& source_name = "<string>");

}  // namespace pitchlab::sim
