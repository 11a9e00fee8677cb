#pragma once
// Gaps the traversability grid bridged only on the hypothesis that they lie between scan lines
// (TraversabilityGrid::line_gap: wider, between the points that bound them, than the wheels span),
// checked from close by. A nodding laser's lines meet level ground h below it
// dtheta (d^2 + h^2) / h apart at distance d (dtheta: the pitch step between lines), so within
// sqrt(cell h / dtheta - h^2) of the laser (2.57 m for the P3's LMS200: h 0.54 m, 0.45 deg steps,
// 0.1 m cells) they lie closer than a map cell and leave no gap a cell wide: a gap that a scan from
// there still shows is a crack, a hole or a shadow, not ground the lines skipped. The terrain's
// 0.25 m cracks, seen from 3 m, were such bridges, and the robot drove into them.

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

/// What a line gap seen from close, still a gap, is.
enum class RefutedGap : std::uint8_t {
  kNone = 0,   ///< not refuted
  kUnseen,     ///< rays crossed it above the ground around it: ground may be there, unseen
  kDepression  ///< a ray crossed it below that ground: the ground falls away (a crack, a hole)
};

/// A ray this far below the line between a gap's ends is below the ground, not on it: the real
/// LMS200's floor heights scatter 3.3 mm (0-2 m) and 8.3 mm (2-4 m) about their neighbours'
/// (sensor_realism, 3DTK corridor), and a refuted gap lies within ~2.6 m [m].
inline constexpr double kBelowGround_m = 0.01;

/// Refutes the line-gap cells of `grid` within `radius_m` of `laser_xy` in the half plane ahead
/// of `heading_rad` (the laser's field of view): a scan from there would have filled them were
/// they ground between lines. Each becomes kDepression when `layers`' clearance over it lies more
/// than kBelowGround_m below the bridge's height, else kUnseen. `refuted` holds one entry per
/// cell of `grid` (sized on first use); cells refuted before keep their entry. Returns how many
/// cells it newly refuted.
std::size_t RefuteLineGaps(const planning::TraversabilityGrid& grid,
                           const mapping::ElevationLayers& layers, const Eigen::Vector2d& laser_xy,
                           double heading_rad, double radius_m, std::vector<RefutedGap>& refuted);

/// Applies the refutations to the cells of `layers` still unknown: a kDepression becomes a drop,
/// which the footprint keeps off with its margin (left unknown, a path alongside a crack put a
/// wheel into it); a kUnseen loses the rays that made it a bridge and stays unknown for the
/// planner's unknown policy (as drops, floor gaps beside a yard's wall end closed the short way
/// round). Cells seen since keep what the map says; the mission's recovery doubts drops as it
/// doubts every inferred one, and looks from closer.
void MarkRefutedGaps(mapping::ElevationLayers& layers, const std::vector<RefutedGap>& refuted);

}  // namespace pitchlab::mission
