#pragma once
// How far the robot drives along its plan before the next scan: over what was seen, stopping
// short of the first unobserved cell.

#include <optional>

#include "pitchlab/mission/path_follower.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// How far a plan runs over known ground from its start.
struct KnownStretch {
  double length_m = 0;      ///< along the plan to the first cell not known [m]
  bool to_the_end = false;  ///< every cell of the plan is known
};

/// The stretch of `path` (its start, the robot's own cell, counts) up to the first waypoint whose
/// cell the laser has not made known ground: unobserved in `grid`, or a line gap (ground only
/// until a look from closer says otherwise, line_gaps.hpp). A cell seen without a supported slope
/// counts as seen (benchmarks/README.md, session 42: counting it as unseen made the robot stop
/// short of such cells and look again, and moved no crossing of a true hazard).
KnownStretch PlanKnownStretch(const planning::Path& path, const planning::TraversabilityGrid& grid);

/// A drive's length, or only a turn to face the path.
struct DriveLength {
  double length_m = 0;     ///< along the path [m]; meaningless when turn_only
  bool turn_only = false;  ///< only turn to face the path, so the next scan sees it
};

/// The drive of one stop. The robot drives at most `drive_per_stop_m`, and stops
/// `unknown_margin_m` short of the plan's first unobserved cell (`plan_known_m` along it); a plan
/// seen to its end (`seen_to_the_end`: plan_known_m is its whole length) is driven to its end. When
/// that leaves less than the margin, it only turns to face the path; after a stop that only
/// turned (`last_turned_only`), what it did not see is in the laser's blind zone just ahead, and it
/// drives a metre (at most a stop's drive) onto it. The metre is for that case only: taken at every
/// stop it carried the robot past the margin up to a crack's unseen cells 0.55 m on, where it
/// rolled 30 deg turning on the rim (terrain seed 18). A recovery that plans through doubted cells
/// (`plan_to_doubt_m`, along the plan to the first of them) stops the margin short of them, also
/// after a turn. A length below MinDriveLength is no progress: the caller ends the run.
DriveLength PlanDriveLength(double drive_per_stop_m, double unknown_margin_m, double plan_known_m,
                            bool seen_to_the_end, bool last_turned_only,
                            std::optional<double> plan_to_doubt_m);

/// The shortest drive that is progress [m]: 0.1 m, or the path follower's goal tolerance where that
/// is more, since the follower counts a path that short as driven before it moves (gully seed 1
/// was given 0.124 m drives against a 0.15 m tolerance, stood still, and scanned from the same
/// spot 28 times until its stop limit).
double MinDriveLength(const PurePursuitConfig& follower);

}  // namespace pitchlab::mission
