#pragma once
// Returns whose place along the beam the beam's own footprint leaves unsure. A beam of divergence
// delta meets a surface at incidence alpha in a patch that spans r * delta * tan(alpha) in range:
// the echo comes back from anywhere in it (the LMS200 model's incidence noise rests on this, and
// on the real scans' residuals). Near a surface's end the patch runs past it, and the reading is
// a point on the beam's line past the end: grazing a wall towards a door, the returns put
// wall-high points up to half a patch into the doorway (0.16 m at 6.5 m, 86 deg), and an office
// door 1.05 m wide, which the P3-AT passes with 0.2 m to spare, closed on the measured LMS200
// model (issue 16). On ground that spread slides a point along the ground: its height stays right.
//
// The surface of each return comes from its neighbours in the organised scan: the neighbour in its
// line and the one in the next line whose ranges are nearest its own (the same surface when there
// is one). A return is "grazed" when
//   - that surface is steeper than ground (its normal more than `max_ground_tilt_rad` from
//     base_link's z),
//   - the return lies between its two in-line neighbours in range, as on a surface that the
//     beams meet one after another, each farther than the last (a thin leg or pole hit by a beam
//     or two has both neighbours behind it, on the background, and is no grazed surface), and
//   - its footprint's range spread, r * delta * tan(incidence), exceeds `max_spread_m`.
// A return that lies between its in-line neighbours is also flagged, whatever its surface, when
// each of them is so far from it in range that the surface joining them would spread the
// footprint over more than `max_spread_m` (delta |dr| / dtheta for beams dtheta apart: 0.2 m of
// range between the LMS200's 0.5 deg beams): a mixed pixel. A beam straddling a depth edge (a door
// jamb against the room behind it) returns a blend of both ranges, a point in the air between the
// two surfaces (Lms200Config::mixed_pixels, as real LMS scanners do); in an office doorway, seen
// from 7 m, such points stood 0.3-1.4 m high in the opening and closed a 1.05 m door as steps.
// A thin pole hit by one beam has both neighbours behind it, is not between them, and is kept.
// A return without neighbours on both sides in its line, or without one in an adjacent line
// (for the grazed surface), is never flagged (nothing to measure its surface with).

#include <vector>

#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors {

struct GrazingConfig {
  /// Full beam width [rad]; Lms200Config::beam_divergence_deg (0.25 deg).
  double beam_divergence_rad = 0.25 * 3.14159265358979323846 / 180.0;
  /// Spread along the beam beyond which a return's place is unsure [m]: the elevation map's cell
  /// (a point that may lie a cell further cannot be given a cell).
  double max_spread_m = 0.1;
  /// Surfaces tilted less than this are ground, whatever the spread [rad]: 45 deg, more than
  /// twice the P3-AT's 19 deg (35 %) grade, so every slope the robot could meet counts as ground.
  double max_ground_tilt_rad = 3.14159265358979323846 / 4.0;
};

/// One flag per point of `scan` (in its order): true where the return is grazed (above). The laser
/// origin of each line is `mount`'s at the line's encoder pitch. O(points).
std::vector<bool> GrazedReturns(const Scan3D& scan, const MountConfig& mount,
                                const GrazingConfig& config = {});

}  // namespace pitchlab::sensors
