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
// The surface of each return is the least-squares plane of the returns of its beam and of its
// in-line neighbour nearest in range, each in the lines before and after (those within twice that
// neighbour's range step, plus max_spread_m): with the measured noise a grazed return moves
// decimetres along its beam, nearly in the surface, so six returns span it where two neighbour
// vectors, mostly noise, did not. A return is "grazed" when
//   - that surface is steeper than ground (its normal more than `max_ground_tilt_rad` from
//     base_link's z), and
//   - the return lies between its two in-line neighbours in range, as on a surface that the
//     beams meet one after another (a neighbour that gave no return, a dropout or a beam into
//     the open, counts as beyond it), or is nearer (farther) than both with the nearer one
//     within the range scatter of its own beam's lines before and after:
//     the end of a grazed surface, whose noise put it in front of the next beam's (a door jamb's
//     last return, 0.37 m into the doorway); a thin leg or pole hit by a beam or two has the
//     background on both sides, far beyond its own lines' scatter, and is kept, and
//   - its footprint's range spread, r * delta * tan(incidence), exceeds `max_spread_m`.
// A return that lies between its in-line neighbours on a surface steeper than ground is also
// flagged when each of them is so far from it in range that the surface joining them would spread
// the footprint over more than `max_spread_m` (delta |dr| / dtheta for beams dtheta apart: 0.2 m
// of range between the LMS200's 0.5 deg beams) and the ranges jump on both sides (a smooth
// surface's steps change by less than a factor 2 from beam to beam): a mixed pixel, a blend of a
// jamb and the room behind it in the air between them (Lms200Config::mixed_pixels, as real LMS
// scanners do), or the tail of the grazing noise. A return with neither in-line neighbour, or
// whose neighbours span no plane (nothing then tells a wall from far ground), is never flagged.

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
