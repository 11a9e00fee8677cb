#pragma once
// A 3D scan from one pitch sweep, and Eq. 1: how a reading becomes a point in base_link.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/laser_line.hpp"

namespace pitchlab::sensors {

/// Where the laser sits on the robot (calibratable). Frames: base_link -> laser_mount (the pitch
/// axis, parallel to base_link's y at pitch 0) -> laser (mirror centre).
struct MountConfig {
  Eigen::Vector3d t_base_mount_m{0.10, 0.0, 0.45};  ///< pitch axis position in base_link [m]
  Eigen::Vector3d t_mount_laser_m{0.0, 0.0, 0.09};  ///< mirror centre from the pitch axis [m]
  Eigen::Vector3d misalignment_rpy_rad{0.0, 0.0,
                                       0.0};  ///< scan plane vs mount, roll/pitch/yaw [rad]

  /// T_mount_laser at zero pitch: the misalignment rotation and the mirror offset.
  Eigen::Isometry3d MountToLaser() const;
  /// T_base_laser at pitch `gamma_rad`.
  Eigen::Isometry3d BaseToLaser(double gamma_rad) const;
};

/// Eq. 1 plus the mount: a reading of range `rho_m` at beam angle `theta_rad` with the mount at
/// pitch `gamma_rad`, as a point in base_link [m].
Eigen::Vector3d BeamPointInBase(double rho_m, double theta_rad, double gamma_rad,
                                const MountConfig& mount);

/// Farthest a coordinate (a point, a pose's translation) may lie from its frame's origin [m]:
/// float32, which PCD's x y z and the maps' points use, spaces values 7.8 mm apart from 65.5 km
/// (2^16 m) up, near the LMS200's 10 mm cm-mode resolution; beyond 100 km the numbers cannot
/// hold what the sensor measured, so a value past it is a corrupt or foreign-unit file.
constexpr double kMaxCoordinate_m = 1.0e5;

/// One point of a 3D scan, in base_link.
struct ScanPoint {
  float x = 0, y = 0, z = 0;  ///< [m]
  float range_m = 0;          ///< measured range [m]
  std::uint16_t line = 0;     ///< index of the line (pitch step) it came from
  std::uint16_t beam = 0;     ///< index of the reading within its line
  double stamp_s = 0;         ///< its line's stamp [s]
};

/// A full 3D scan: valid returns as points in base_link, the raw lines, and (in simulation) truth.
struct Scan3D {
  double stamp_s = 0.0;           ///< first line's stamp [s]
  double duration_s = 0.0;        ///< first line's start to last line's end [s]
  std::vector<ScanPoint> points;  ///< valid returns, line-major
  std::vector<LaserLine> lines;   ///< what the scanner delivered, with encoder pitch
  std::size_t no_returns = 0;     ///< readings flagged no-return
  std::size_t over_ranges = 0;    ///< readings flagged over-range
  /// The points are in base_link as it stood at the last line: each line was turned by the
  /// base's rotation since it, as an attitude sensor measured it (AssembleScan's attitudes).
  /// Otherwise they are in base_link as it stood at each line (one frame while the base is still).
  bool deskewed = false;
  /// The largest rotation of the base between a line and the last one an attitude sensor sensed,
  /// also when it was too small to correct (PitchingScanSource); 0 without a sensor [rad].
  double deskew_max_rad = 0.0;
  bool has_truth = false;     ///< T_world_base below is the simulator's ground truth
  bool has_odometry = false;  ///< T_world_base below is the robot's odometry (e.g. a 3DTK .pose)
  /// Pose of the points' frame: base_link when the scan started (at its end when deskewed). Known
  /// when has_truth or has_odometry; otherwise whatever the file held (identity when nothing).
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();
  /// Where the sensor (the laser's mirror centre) stood, in the points' frame [m]; unset when the
  /// source does not say (a foreign PLY or XYZ file). Free-space carving casts rays from it.
  std::optional<Eigen::Vector3d> sensor_origin;
  /// The world the scan was taken in (a simulated world's name, the stem of its MJCF file), so a
  /// tool scoring it against a world's truth can tell it is the right one; empty when unknown.
  std::string world;
};

/// The largest rotation between any of `attitudes` and the last one [rad]; 0 when empty.
double MaxTurnToLast(const std::vector<Eigen::Quaterniond>& attitudes);

/// Builds the 3D scan from lines by Eq. 1 (each line's encoder pitch and the mount). With
/// `attitudes` (one per line: base_link's orientation while that line swept, in any frame fixed to
/// the ground, e.g. an IMU's integrated rates), every line is turned into base_link as it stood at
/// the last line. A robot that rocks on its tyres while the laser nods (its weight moves with the
/// pitch) bends an uncorrected scan: 2 deg of rock moves a return 10 m away by 35 cm.
/// Throws std::invalid_argument when `attitudes` is neither empty nor one per line.
Scan3D AssembleScan(std::vector<LaserLine> lines, const MountConfig& mount,
                    const std::vector<Eigen::Quaterniond>& attitudes = {});

/// The points of `scan`, assembled with `from`, as the mount `to` places them: each point taken
/// back into its line's laser frame through `from` and out through `to` (Eq. 1 at the line's
/// encoder pitch with the other mount), the sensor origin with it. Ranges, lines and stamps stay.
/// A deskewed scan's lines were also turned by the base's rotation since; the two turns commute
/// to the product of their angles (a 0.3 deg mount change after a 1 deg rock: 1e-4 rad).
/// Throws std::invalid_argument for a point whose line the scan does not hold.
void ReassembleScan(Scan3D& scan, const MountConfig& from, const MountConfig& to);

}  // namespace pitchlab::sensors
