#pragma once
// Scans as PCL PCD files, the format every point-cloud tool opens (pcl_viewer, CloudCompare, Open3D).

#include <string>

#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors {

/// Writes `scan` as a binary PCD: fields x y z range (float32, [m]), ring (uint16: line index),
/// beam (uint16), stamp (float64, [s]); points in base_link. VIEWPOINT holds T_world_base (ground
/// truth in simulation, odometry, or identity when unknown), and two header comments (PCD readers
/// skip '#' lines) what it is and where the sensor stood: `# pose truth|odometry|unknown`,
/// `# sensor_origin x y z` [m, points' frame] when known, `# world NAME` when scan.world is one word. Written to a temporary file and renamed,
/// so a failure leaves no partial file. An error names the path and the reason.
[[nodiscard]] Result<void> WriteScanPcd(const Scan3D& scan, const std::string& path);

/// Reads a PCD written by WriteScanPcd (or any PCD with float32 or float64 x y z, its data ascii,
/// binary or binary_compressed; NaN points count as no_returns): points, the VIEWPOINT as T_world_base, and our comments (a file of ours without the origin
/// comment leaves sensor_origin unset). Without them (a foreign PCD) the PCD convention holds:
/// VIEWPOINT is where the points were taken from, so sensor_origin = (0,0,0), and has_truth is set
/// when the VIEWPOINT is not the identity. Without a range field, range_m is the distance from
/// the sensor origin. Lines are not restored. A header promising more than the file holds (checked
/// before anything is allocated), data that is not what the header says and a VIEWPOINT that is not a pose (non-finite, beyond
/// kMaxCoordinate_m, a quaternion far from unit length) are errors naming the file.
[[nodiscard]] Result<Scan3D> ReadScanPcd(const std::string& path);

}  // namespace pitchlab::sensors
