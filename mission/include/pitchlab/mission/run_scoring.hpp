#pragma once
// Scores a simulated mission against ground truth: pose errors, the driven path costed on the
// true map against the true optimum, closest approach to a truly forbidden cell, tilt.

#include <optional>
#include <string>
#include <vector>

#include "pitchlab/mission/mission.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// Hazard cells counted by kind: a step, a drop, too steep [1].
struct HazardKinds {
  std::size_t step = 0, drop = 0, too_steep = 0;
  /// Counts `b` when it is one of the three (free, near a hazard and unknown are not).
  void Count(planning::Blocked b) {
    step += b == planning::Blocked::kStep;
    drop += b == planning::Blocked::kDrop;
    too_steep += b == planning::Blocked::kTooSteep;
  }
  std::size_t Total() const { return step + drop + too_steep; }
};

/// The map's plane tilt against the truth's over the cells whose true tilt lies in [lo, hi) deg,
/// both seen and neither a step nor a drop in the truth: whether the map reads slopes as steep as
/// they are, unbiased by what the planner made of them (the missed cells alone are the ones it
/// read too level).
struct TiltAgainstTruth {
  double lo_deg = 0, hi_deg = 0;
  std::size_t cells = 0;        ///< with a true tilt in the bin, seen in the map [1]
  std::size_t unsupported = 0;  ///< of those, the scan did not support the map's slope [1]
  /// Over the supported ones: map minus truth, median and the 10th / 90th percentiles [deg]
  /// (0 when none).
  double median_error_deg = 0, p10_error_deg = 0, p90_error_deg = 0;
};

struct RunScore {
  double final_translation_error_m = 0;             ///< last estimate vs truth [m]
  double final_rotation_error_deg = 0;              ///< [deg]
  double max_registration_translation_error_m = 0;  ///< over stops merged by registration [m]
  double max_registration_rotation_error_deg = 0;   ///< [deg]
  /// Registration's own error, without the drift it inherits: each merged stop's motion since the
  /// previous merged stop, estimated vs true. Largest and 95th percentile over the run's steps
  /// (0 when fewer than one step) [m] / [deg].
  int registration_steps = 0;
  double registration_step_max_m = 0, registration_step_p95_m = 0;
  double registration_step_max_deg = 0, registration_step_p95_deg = 0;
  double true_distance_m = 0;               ///< driven, by ground truth [m]
  double final_distance_to_goal_m = 0;      ///< true position to goal [m]
  double max_true_tilt_deg = 0;             ///< [deg]
  std::optional<double> true_optimal_cost;  ///< start to goal on the true map (none: no path)
  std::string true_optimum_note;            ///< why there is none
  double driven_cost_on_true_map = 0;       ///< the true trajectory's cells, costed by Eq. 5
  std::optional<double> cost_ratio;         ///< driven / optimal (>= 1 up to discretisation)
  std::size_t forbidden_cells_crossed = 0;  ///< truly forbidden cells under the true trajectory
  /// Their centres, in the order driven (one per count above) [m]: where a run that was unsafe
  /// was, for its pictures.
  std::vector<Eigen::Vector2d> forbidden_crossed_at;
  /// Of those, cells that are a true step, drop or too steep themselves (the rest are within half
  /// the robot's width of one, or unknown in the truth) [1].
  std::size_t hazard_cells_crossed = 0;
  /// Smallest distance from the robot's centre to a truly hazardous cell (step, steep, drop) [m];
  /// infinity when none is within 5 m of the trajectory.
  double closest_hazard_m = 0;
  Eigen::Vector2d closest_hazard_at{0, 0};  ///< where the robot was then [m]
  /// The final map's hazards (step, drop, too steep) against the true ones, cell by cell over the
  /// cells both know: a run that ends with no path was most often walled in by false hazards, and
  /// unlike success these counts change smoothly with the map's quality [1].
  std::size_t map_cells_compared = 0;
  /// Hazard in the map, truly free (not even near one) and within the robot's reach: joined to
  /// the start by the moves the true map allows (planning::ReachableCells). A false hazard costs a run a way it truly has;
  /// a truly free cell it cannot reach (a parked car's roof, cast from above, flat and more than
  /// the footprint from its edge) is no way to close [1].
  std::size_t false_hazard_cells = 0;
  /// Hazard in the map where the truth is free but out of the robot's reach (not counted above)
  /// [1].
  std::size_t false_hazard_cells_out_of_reach = 0;
  /// Of those, what the map took them for [1].
  HazardKinds false_as;
  std::size_t missed_hazard_cells = 0;  ///< free in the map, truly a hazard
  /// Of those, what the truth calls them [1].
  HazardKinds missed_as;
  /// The missed too-steep cells' plane tilt, the map's and the truth's, medians [deg] (0 when
  /// none): whether the map reads steep ground a little or much too level. Cells whose slope the
  /// scan did not support have no tilt in the map (counted, not in the median).
  double missed_steep_map_tilt_deg = 0;
  double missed_steep_true_tilt_deg = 0;
  std::size_t missed_steep_tilt_unknown = 0;
  /// The map's tilt against the truth's over all cells, binned by the true tilt: below half the
  /// planning limit, from half to the limit, beyond it.
  std::vector<TiltAgainstTruth> tilt_against_truth;
  /// Of hazard_cells_crossed, what the truth calls them [1].
  HazardKinds crossed_as;
  /// The true hazard cells the footprint came over: those the centre crossed and those within
  /// the footprint's reach (planning::FootprintReach) of a forbidden cell it crossed, by kind [1].
  HazardKinds touched;
  /// Of the too-steep ones, the steepest true plane tilt, and the limit the truth judged them by
  /// (the planner's max_inclination) [deg]; 0 when none. A cell half a degree over the planning
  /// limit (terrain: 16 deg, the loaded P3-AT tips at 31) is not a cliff's edge.
  double touched_steepest_deg = 0;
  double too_steep_limit_deg = 0;
};

/// How a map's cell compares with the truth's (both on one grid): kNotCompared where either does
/// not know the cell (no height and no hazard inferred: a drop may have no points, only rays).
enum class HazardVerdict { kNotCompared, kAgree, kFalseHazard, kMissedHazard };
/// kFalseHazard: a step, drop or too steep cell of `estimated` that `truth` calls free (not even
/// near a hazard); kMissedHazard: a true hazard `estimated` calls free.
HazardVerdict CompareHazard(const planning::TraversabilityGrid& estimated,
                            const planning::TraversabilityGrid& truth, std::size_t k);

/// `truth` is the true traversability over the mission's map area, `estimated` the final map's on
/// the same grid; `start_m`/`goal_m` world [m]; `via_m` the waypoints the mission drove through
/// (the true optimum goes through them too: PlanRoute).
RunScore ScoreRun(const MissionResult& result, const planning::TraversabilityGrid& truth,
                  const planning::TraversabilityGrid& estimated,
                  const Eigen::Vector2d& start_m, const Eigen::Vector2d& goal_m,
                  planning::Algorithm algorithm, const std::vector<Eigen::Vector2d>& via_m = {});

}  // namespace pitchlab::mission
