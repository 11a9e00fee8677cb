#pragma once

#include <optional>
#include <string>

// Forward declaration as in <mujoco/mjmodel.h>, so this header does not pull MuJoCo in.
typedef struct mjModel_ mjModel;

namespace pitchlab::worlds {

/// A WGS84 point.
struct GeodeticPoint {
  double latitude_deg = 0.0;   ///< [deg], north positive
  double longitude_deg = 0.0;  ///< [deg], east positive
  double height_m = 0.0;       ///< ellipsoidal height (or the DEM's vertical datum) [m]
};

/// An axis-aligned rectangle in the world frame [m].
struct Bounds2d {
  double x_min_m = 0.0;  ///< [m]
  double y_min_m = 0.0;  ///< [m]
  double x_max_m = 0.0;  ///< [m]
  double y_max_m = 0.0;  ///< [m]
};

/// A planar robot pose on the ground.
struct StartPose {
  double x_m = 0.0;      ///< [m]
  double y_m = 0.0;      ///< [m]
  double yaw_rad = 0.0;  ///< heading about z, counter-clockwise from +x [rad]
};

/// A point on the ground the robot should reach.
struct GoalPoint {
  double x_m = 0.0;  ///< [m]
  double y_m = 0.0;  ///< [m]
};

/// What a world says about itself through its MuJoCo custom fields (`pitchlab:*`).
struct WorldMetadata {
  std::string description;                       ///< one line, empty when absent
  std::optional<GeodeticPoint> geodetic_origin;  ///< the world origin on WGS84, if georeferenced
  Bounds2d bounds;                               ///< where a robot may be placed [m]
  StartPose default_start;                       ///< a free, flat spot
  /// Where the default closed-loop run drives to, if the world names one.
  std::optional<GoalPoint> default_goal;
};

/// Custom field names, shared by the writers and the reader.
inline constexpr const char* kDescriptionField = "pitchlab:description";
/// Numeric field "lat_deg lon_deg height_m".
inline constexpr const char* kGeodeticOriginField = "pitchlab:geodetic_origin";
/// Numeric field "xmin ymin xmax ymax" [m].
inline constexpr const char* kBoundsField = "pitchlab:bounds";
/// Numeric field "x_m y_m yaw_deg".
inline constexpr const char* kDefaultStartField = "pitchlab:default_start";
/// Numeric field "x_m y_m": the default run's goal.
inline constexpr const char* kDefaultGoalField = "pitchlab:default_goal";

/// Reads the metadata of a compiled world. Absent fields get defaults (no description, no geodetic
/// origin, bounds = the model's extent around its centre, start at the origin), so any MJCF is a
/// world. Throws std::invalid_argument naming the field when one has the wrong size or values.
WorldMetadata ReadWorldMetadata(const mjModel* model);

/// The `<custom>` MJCF element holding `metadata` (for world writers), indented by two spaces.
std::string FormatMetadataMjcf(const WorldMetadata& metadata);

}  // namespace pitchlab::worlds
