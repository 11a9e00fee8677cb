#pragma once
// A nodding laser's mount calibrated by the floor the robot stands on. The scan plane of a
// nodding LMS200 sits on its pitch axis off by a fraction of a degree in roll, pitch and yaw
// (sensors::MountConfig::misalignment_rpy_rad). The error lies inside the pitching frame, so it is
// no fixed rotation of the scan: a roll of the scan plane tilts a level line sideways, but turns a
// line looking down at the floor about the vertical, and a yaw within the scan plane does the
// reverse. On the floor a line at pitch gamma crossed, both read as a sideways slope of
// roll cos(gamma) + yaw sin(gamma); the lines that crossed the floor at different pitches tell the
// two apart, the pitch is the forward slope of all of them. A fixed rotation levelling the floor
// (the floor's mean of those slopes) set the floor right and tilted the walls the level lines see
// by yaw sin(gamma): in the office, where walls steer the registration, that cost two of twenty
// runs (benchmarks/README.md, "The mount calibrated by the floor at the start").

#include <cstddef>
#include <string>

#include <Eigen/Core>

#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::mapping {

struct MountFromFloorConfig {
  /// Where the floor is looked for: the levelling's candidates, 0.5-4 m from the laser.
  GroundLevelConfig ground;
  /// A floor tilted more than this in base_link is no mount error: the robot does not stand on
  /// the plane it sees (a ramp's foot, a rock under a wheel) [rad]. 2 deg: eight times the
  /// measured model's 0.25 deg per axis, well below the 3DTK rig's 3-5 deg unmounted frame tilt
  /// that a ground robot's mount would never be built with.
  double max_tilt_rad = 0.0349065850;
  /// The prior on each angle of the correction, a mount assembled to within this [rad]: 1 deg,
  /// four times the measured per-axis spread. It only holds an angle the floor does not tell
  /// (yaw, when every floor line was taken at one pitch) near the nominal mount.
  double prior_sigma_rad = 0.0174532925;
};

/// The mount the floor says the laser is on.
struct MountFromFloor {
  sensors::MountConfig mount;  ///< the nominal mount with the misalignment found
  Eigen::Vector3d correction_rpy_rad = Eigen::Vector3d::Zero();  ///< added to the nominal's
  Eigen::Vector3d sigma_rpy_rad = Eigen::Vector3d::Zero();  ///< 1-sigma of each angle [rad]
  double floor_z_m = 0;          ///< the floor's height in base_link [m]
  double tilt_before_rad = 0;    ///< the floor's tilt with the nominal mount [rad]
  double residual_before_m = 0;  ///< RMS height of the floor points about their plane, nominal
  double residual_m = 0;         ///< RMS height of the floor points about z = floor_z_m, found
  std::size_t points = 0;        ///< floor points the fit used [1]
};

/// Calibrates `nominal` by the floor `scan` (assembled with `nominal`, points in base_link, its
/// lines kept) stands on, base_link's z = const plane: the floor 0.5-4 m from the laser is found
/// (FitGroundLevel), its points are taken back into their line's laser frame, and the roll, pitch
/// and yaw added to the mount's misalignment that put them on one level plane are solved for
/// (Gauss-Newton, the prior above). Fails, naming why, when the scan holds no lines, no floor is
/// found, or the floor tilts more than max_tilt_rad.
[[nodiscard]] Result<MountFromFloor> CalibrateMountFromFloor(const sensors::Scan3D& scan,
                                                             const sensors::MountConfig& nominal,
                                                             const MountFromFloorConfig& config = {});

}  // namespace pitchlab::mapping
