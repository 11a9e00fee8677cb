#pragma once
// Point clouds from the files users bring: PCD, 3DTK "uos" scans, PLY, plain XYZ text. Every
// reader returns points in REP-103 metres, or an error that names the file (and the line or point
// where there is one); nothing is half-read into a result.

#include <string>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors {

/// The formats ReadCloudFile reads, one per line, for --help texts.
const char* CloudFormatsHelp();

/// Reads a point cloud, the format chosen by the extension (case-insensitive): .pcd (ReadScanPcd),
/// .3d (Read3dtkScan), .ply (ReadPly), .xyz / .txt (ReadXyz). An unknown extension is an error;
/// so is a point CheckPointsPlausible rejects.
[[nodiscard]] Result<Scan3D> ReadCloudFile(const std::string& path);

/// Every point of `scan` (read from `path`) lies within kMaxCoordinate_m of its frame's origin on
/// each axis; else an error naming the file, the first such point's index and its coordinates.
[[nodiscard]] Result<void> CheckPointsPlausible(const Scan3D& scan, const std::string& path);

/// A 3DTK "uos" scan `scanNNN.3d` (centimetres, 3DTK's left-handed x right, y up, z forward) with
/// its odometry `scanNNN.pose` beside it, in REP-103 metres: points in the scanner's frame
/// (sensor_origin (0,0,0)), T_world_base the converted pose (has_odometry). Readings of 3DTK's
/// maximum range (32.76 m) are no-returns (counted in no_returns); returns under 48 cm are dropped
/// (3DTK's config.ini). A missing or unreadable .pose is an error naming the file looked for.
[[nodiscard]] Result<Scan3D> Read3dtkScan(const std::string& path);

/// A 3DTK `.pose` file ("x y z" [cm], then "rx ry rz" [deg]; R = Rx Ry Rz), as a REP-103 pose [m].
[[nodiscard]] Result<Eigen::Isometry3d> Read3dtkPose(const std::string& path);

/// The last pose of a slam6d `.frames` file (each line a 4x4 matrix in column-major order [cm] and
/// a type flag; the last line is the final registered pose), as a REP-103 pose [m].
[[nodiscard]] Result<Eigen::Isometry3d> Read3dtkFrames(const std::string& path);

/// A 3DTK point [cm] in REP-103 [m]: x = z3 / 100, y = -x3 / 100, z = y3 / 100.
Eigen::Vector3d PointFrom3dtk(const Eigen::Vector3d& p_cm);

/// A 3DTK transform (p_world = R p + t, t in [cm]) in REP-103 [m]: C T C^-1 with C the axis
/// change of PointFrom3dtk, so PointFrom3dtk(T3 p) = result * PointFrom3dtk(p).
Eigen::Isometry3d TransformFrom3dtk(const Eigen::Matrix4d& T_cm);

/// 3DTK's pose vector: translation [cm], rotations rx ry rz [deg], R = Rx Ry Rz, as a 4x4 in
/// 3DTK's own frame and units (what slam6d's EulerToMatrix4 builds).
Eigen::Matrix4d Matrix3dtkFromPose(const Eigen::Vector3d& t_cm, const Eigen::Vector3d& r_deg);

/// A PLY file (ascii, binary_little_endian, binary_big_endian): the `vertex` element's x y z, any
/// scalar type; other properties and elements (faces, before or after) are skipped. Sensor origin
/// unset unless a `comment` or `obj_info` line reads `sensor_origin x y z` [m].
[[nodiscard]] Result<Scan3D> ReadPly(const std::string& path);

/// Plain text, one point a line: x y z [m] separated by spaces, tabs or commas, further columns
/// ignored; blank lines and comment lines ('#', or '//' as CloudCompare writes) skipped. Sensor
/// origin unset. A line that is not three numbers is an error naming the file and the line.
[[nodiscard]] Result<Scan3D> ReadXyz(const std::string& path);

/// Sets scan.sensor_origin to `origin_m` (points' frame [m]) and every point's range_m to its
/// distance from it.
void SetSensorOrigin(Scan3D& scan, const Eigen::Vector3d& origin_m);

}  // namespace pitchlab::sensors
