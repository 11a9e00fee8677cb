#pragma once
// Scans as PCL PCD files, the format every point-cloud tool opens (pcl_viewer, CloudCompare, Open3D).

#include <string>

#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors {

/// Writes `scan` as a binary PCD: fields x y z range (float32, [m]), ring (uint16: line index),
/// beam (uint16), stamp (float64, [s]); points in base_link. VIEWPOINT holds T_world_base (ground
/// truth in simulation, identity when unknown). Written to a temporary file and renamed, so a
/// failure leaves no partial file. An error names the path and the reason.
[[nodiscard]] Result<void> WriteScanPcd(const Scan3D& scan, const std::string& path);

/// Reads a PCD written by WriteScanPcd (or any PCD with x y z): points, and the VIEWPOINT as
/// T_world_base with has_truth set when it is not the identity. Lines are not restored.
[[nodiscard]] Result<Scan3D> ReadScanPcd(const std::string& path);

}  // namespace pitchlab::sensors
