#pragma once
// Gaps the traversability grid bridged (BridgeScanGaps: unknown cells between ground, crossed by
// rays, read as ground between scan lines), checked from close by. A nodding laser's lines meet
// level ground h below it dtheta (d^2 + h^2) / h apart at distance d (dtheta: the pitch step
// between lines), so within sqrt(cell h / dtheta - h^2) of the laser (2.57 m for the P3's LMS200:
// h 0.54 m, 0.45 deg steps, 0.1 m cells) they lie closer than a map cell and leave no gap a cell
// wide: a gap that a scan from there still shows is a crack, a hole or a shadow, not ground the
// lines skipped. That holds for every bridge, also one narrower than the wheels span: its width
// is measured between the points that bound it, and a crack's points lie on its walls, below
// the rims (terrain seed 7: a 0.25 m V-groove 0.12 m deep read as a 0.2 m gap, the robot drove
// across it and pitched 34 deg). The terrain's 0.25 m cracks, seen from 3 m, were such bridges,
// and the robot drove into them.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::mission {

/// Within what distance of the laser a scan's lines lie closer than `cell_m` on level ground
/// `laser_height_m` below it: sqrt(cell_m h / dtheta - h^2), dtheta the median pitch step between
/// the scan's consecutive lines [m]. 0 for a scan of fewer than two lines or no pitch step.
double DenseLinesRadius(const sensors::Scan3D& scan, double laser_height_m, double cell_m);

/// How far ahead of the laser (at pitch 0, along base_link's x) the scan's lines begin to meet
/// level ground under the robot (base_link's z = 0): where the steepest line's forward beam
/// meets it. A pitched scan plane meets level ground along a line across the robot, at the same
/// forward distance for every beam, so nothing nearer is seen by any [m]. +inf for a scan with
/// no line below the horizon.
double NearestGroundAhead(const sensors::Scan3D& scan, const sensors::MountConfig& mount);

/// What a bridged gap seen from close, still a gap, is.
enum class RefutedGap : std::uint8_t {
  kNone = 0,   ///< not refuted
  kUnseen,     ///< rays crossed it above the ground around it: ground may be there, unseen
  kDepression  ///< a ray crossed it below that ground: the ground falls away (a crack, a hole)
};

/// A ray this far below the line between a gap's ends is below the ground, not on it: the real
/// LMS200's floor heights scatter 3.3 mm (0-2 m) and 8.3 mm (2-4 m) about their neighbours'
/// (sensor_realism, 3DTK corridor), and a refuted gap lies within ~2.6 m [m].
inline constexpr double kBelowGround_m = 0.01;

/// Refutes the bridged cells of `grid` (unknown in `layers`, ground in `grid`) that a scan from
/// `laser_xy` saw from where its lines are denser than the cells: within `radius_m` of it, and
/// ahead of `heading_rad` by at least `near_m` (NearestGroundAhead: nearer, the scan sees no
/// ground). Were they ground, the scan would have filled them. Each becomes kDepression when
/// `layers`' clearance over it lies more than kBelowGround_m below the bridge's height, else
/// kUnseen. `refuted` holds one entry per cell of `grid` (sized on first use); cells refuted before
/// keep their entry. Returns how many cells it newly refuted.
std::size_t RefuteBridges(const planning::TraversabilityGrid& grid,
                          const mapping::ElevationLayers& layers, const Eigen::Vector2d& laser_xy,
                          double heading_rad, double near_m, double radius_m,
                          std::vector<RefutedGap>& refuted);
/// Applies the refutations to the cells of `layers` still unknown: a kDepression becomes a drop,
/// which the footprint keeps off with its margin (left unknown, a path alongside a crack put a
/// wheel into it); a kUnseen loses the rays that made it a bridge and stays unknown for the
/// planner's unknown policy (as drops, floor gaps beside a yard's wall end closed the short way
/// round). Cells seen since keep what the map says; the mission's recovery doubts drops as it
/// doubts every inferred one, and looks from closer.
void MarkRefutedGaps(mapping::ElevationLayers& layers, const std::vector<RefutedGap>& refuted);

}  // namespace pitchlab::mission
