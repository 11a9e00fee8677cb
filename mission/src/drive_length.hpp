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

/// The map's tilt of a floor [rad]: the attitude sensor reads the office and urban floors within
/// 0.1 deg, and their cells where the robot drives next within this; terrain's ground seldom is,
/// and its drives slipped even where gentle (5.7 % p95 within 5 deg).
constexpr double kFloorTilt_rad = 1.0 * 3.14159265358979323846 / 180;

/// How far the robot may drive along `path` before the hazards beside it come within what its
/// odometry may have drifted: the arc length to the first waypoint closer to a hazard cell of
/// `grid` (a step, a too-steep or a drop cell) than the footprint's reach plus the drift so far,
/// `error_per_m` times the length of the plan off the floor driven to it (waypoints whose cell's
/// tilt exceeds kFloorTilt_rad). On a floor a skid-steer base's odometry drifts about 1 % (office
/// and urban drives: 0.5 % median), within the planner's safety margin over a whole drive, and it
/// accrues none: cutting the indoor drives short cost the P3-DX, whose 2.5 cm step limit is
/// within a merged floor's outliers, 12 of its 19 goals over office, cluttered and corridor seeds
/// 1..8. Looks no farther than `up_to_m` along the plan (a stop's drive at most: the drift beyond
/// grows the search around a waypoint to metres): returns the arc of the first waypoint at or past
/// it, or the whole path's length, when no waypoint before is that close.
double PlanClearStretch(const planning::Path& path, const planning::TraversabilityGrid& grid,
                        double error_per_m, double up_to_m);

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

/// A drive of `length_m` cut short where the plan's hazards come within the robot's drift
/// (`plan_clear_m`, PlanClearStretch), but to no less than kMinDriftCut_m (or the drive itself):
/// in a passage that narrow the robot goes on a metre at a time, scanning and registering between
/// (a metre's drift at 9 drives in 10 on terrain, 0.19 m, is within the plan's soft clearance).
double CutForDrift(double length_m, double plan_clear_m);
constexpr double kMinDriftCut_m = 1.0;

/// The shortest drive that is progress [m]: 0.1 m, or the path follower's goal tolerance where that
/// is more, since the follower counts a path that short as driven before it moves (gully seed 1
/// was given 0.124 m drives against a 0.15 m tolerance, stood still, and scanned from the same
/// spot 28 times until its stop limit).
double MinDriveLength(const PurePursuitConfig& follower);

}  // namespace pitchlab::mission
