#pragma once
// A small run's report input made from analytic data (a tilted plane with a walled block, an arc
// of a trajectory), for the report's tests: no mission needed, seconds instead of a minute.

#include <filesystem>

#include "run_report.hpp"

namespace pitchlab::mission::testing {

/// A report input for a failed run (reason: kSyntheticReason) whose pictures are written into
/// `folder` (created). `cloud_points` and `surface_side_cells` size the 3D scene.
RunReportInput SyntheticReport(const std::filesystem::path& folder,
                               std::size_t cloud_points = 20000, int surface_side_cells = 80);

/// The failed run's reason, as the page must show it.
inline constexpr const char* kSyntheticReason =
    "no path: the goal at (6.0, 4.0) m is walled in by steps";

}  // namespace pitchlab::mission::testing
