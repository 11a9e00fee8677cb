#pragma once
// How far odometry drifted per metre driven, as the registered scans measured it: the figure
// MissionConfig::drift_per_m plans for, from the run itself (no ground truth needed, so a real
// run reports it too).

#include <cstddef>
#include <vector>

#include "pitchlab/mission/mission.hpp"

namespace pitchlab::mission {

struct OdometryDrift {
  std::size_t drives = 0;   ///< drives measured
  double median_per_m = 0;  ///< [m/m]; 0 when no drive was measured
  double p90_per_m = 0;     ///< nine drives in ten drifted less [m/m]
  double max_per_m = 0;     ///< [m/m]
};

/// Over every registered stop after a drive of at least kMinDriftDrive_m: the horizontal distance
/// between odometry's pose and the registered one, over the distance odometry drove since the
/// stop before (StopRecord::driven_m). Odometry starts each drive from the previous stop's pose,
/// so that is the drive's own drift, plus the two registrations' errors (centimetres).
OdometryDrift MeasureOdometryDrift(const std::vector<StopRecord>& stops);

/// Shorter drives are left out: a turn on the spot or a back-off's few centimetres make a ratio
/// of the registration's own error [m].
constexpr double kMinDriftDrive_m = 0.5;

}  // namespace pitchlab::mission
