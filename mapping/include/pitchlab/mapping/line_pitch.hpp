#pragma once
// A nodding scanner's lines, each set right by the floor it crossed. A pitching laser builds its
// scan from lines taken at the pitch its servo reported; where the true pitch of a line differs
// from the reported one, the whole line is turned about the pitch axis, and the floor it crossed
// is shifted in height by that angle times its distance: the flat floor becomes a washboard of
// one-line stripes, which a map reads as steps. The real 3DTK corridor scans show it: their floor
// lines within 4 m are off by 0.9 deg RMS (up to 3 deg; a jump of 2.7 deg between two
// neighbouring lines), repeatably from scan to scan (benchmarks/README.md, "Line pitch").
//
// The floor within a few metres of the sensor is the reference the map's levelling already takes
// to be flat (ground_level.hpp); each line that crossed it is turned about the pitch axis until
// its floor points lie on the floor plane of all lines. Lines that did not cross that floor keep
// their pitch: nothing in one scan tells their error.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/sensors/lms200.hpp"

namespace pitchlab::mapping {

struct LinePitchConfig {
  /// Points of one line share one elevation about the pitch axis (their rays lie in the line's
  /// plane, whatever their range); sorted elevations that jump by more than this start a new
  /// line [rad]. 0.05 deg: a fifth of the finest line spacing a nodding SICK rig uses (0.25 deg;
  /// the 3DTK rig 0.52 deg), far above the float rounding of a point's elevation.
  double line_gap_rad = 0.000872664626;
  /// A scan whose points do not fall into lines is left alone: fewer lines of min_line_points,
  /// or a smaller share of the points in them, and it is not a nodding scan about the frame's y
  /// axis through the sensor (a rotating scanner, a merged cloud, a simulated scan in base_link).
  std::size_t min_lines = 20;
  double min_line_share = 0.9;
  /// A line's pitch is set from at least this many of its floor points (an LMS line crosses a
  /// 1.5 m wide corridor floor at 2 m in ~80 beams at 0.5 deg) [1].
  std::size_t min_line_points = 20;
  /// The largest pitch error corrected; a line whose floor points ask for more is not crossing
  /// the floor [rad]. 5 deg: above the 3DTK rig's worst line (3.1 deg) with margin, below what
  /// separates the floor from a low obstacle's top seen 1-4 m away.
  double max_correction_rad = 0.0872664626;
  /// The angle between an LMS200's beams within one turn of its mirror [rad]. Its finer modes
  /// interlace turns: at 0.5 deg two 1 deg sweeps offset by 0.5 deg, at 0.25 deg four (LMS200
  /// manual: one turn in 13.3 ms). A nodding rig pitches on between the turns, so each sweep of
  /// a line has a pitch of its own: the 3DTK rig's two sweeps lie ~0.2 deg apart, and 3 deg where
  /// its servo jumps between them (one half of such a line met the floor at 2.2 m, the other at
  /// 3.3 m). A line whose beams lie closer than this is split into its sweeps (beam index modulo
  /// the sweeps), and each is set right on its own; a scan at this step or coarser is not split.
  double sweep_step_rad = sensors::kLms200TurnRad;  // 1 deg
  /// The floor taken as flat: the levelling's candidates (GroundLevelConfig radii) [m].
  GroundLevelConfig ground;
};

/// One line turned onto the floor: the pitch it was recorded at (its points' median elevation
/// below the pitch axis, down positive) and the turn applied (positive: the line lay lower than
/// recorded) [rad].
struct LineCorrection {
  double pitch_rad = 0;
  double correction_rad = 0;
  int sweep = 0;  ///< which of the line's interlaced sweeps (LinePitchConfig::sweep_step_rad)
};

/// What RectifyLinePitch found and did.
struct LinePitch {
  bool nodding = false;          ///< the points fell into lines of one elevation each
  std::size_t lines = 0;         ///< lines of at least min_line_points points [1]
  int sweeps_per_line = 1;       ///< interlaced sweeps each line was split into [1]
  std::size_t corrected = 0;     ///< lines turned onto the floor [1]
  double rms_correction_rad = 0;  ///< RMS of the corrections applied [rad]
  double max_correction_rad = 0;  ///< largest |correction| applied [rad]
  double floor_rms_before_m = 0;  ///< the floor points' RMS distance from the floor plane [m]
  double floor_rms_after_m = 0;   ///< the same after the correction [m]
  std::string note;               ///< why nothing was corrected, when nothing was
  /// Each corrected line, by recorded pitch: the servo's error profile as the floor measured it
  /// (whether it repeats from scan to scan says whether a table could correct it; real_eval).
  std::vector<LineCorrection> line_corrections;
};

/// Sets each line of a nodding scan right by the floor it crossed. `points_m` are in the scan's
/// own frame, whose y axis through `sensor_m` is the pitch axis (3DTK's scans, any scanner that
/// pitches about its own origin); each line (the points of one elevation about that axis) that
/// crossed the floor within the config's radii is turned about the axis by the angle that puts
/// its floor points (robustly: their median) on the floor plane of all corrected lines, the mean
/// correction held at zero (a common offset is a tilt of the frame: the levelling's to remove).
/// Points are changed in place; a scan that is not line-structured, or whose floor cannot be
/// found, is left as it was and the result's note says why. O(n log n).
LinePitch RectifyLinePitch(std::vector<Eigen::Vector3f>& points_m, const Eigen::Vector3f& sensor_m,
                           const LinePitchConfig& config = {});

/// The same for a scan that knows its lines (`lines[l]`: the indices of line l's points; lines of
/// fewer than min_line_points are left as they are), such as pitchlab's own (sensors::ScanPoint::
/// line), whose laser sits off the pitch axis so that a line's points do not share one elevation
/// about it. Each line is turned about the y axis through `axis_m`, the pitch axis (in base_link:
/// the mount's origin). `sweep_of`, when given, says which interlaced sweep each of `lines` is
/// (a caller that split its lines by sweep; reported in each LineCorrection). Throws
/// std::invalid_argument for an index outside `points_m` or a `sweep_of` of another size.
LinePitch RectifyLinePitch(std::vector<Eigen::Vector3f>& points_m, const Eigen::Vector3f& axis_m,
                           const std::vector<std::vector<std::uint32_t>>& lines,
                           const LinePitchConfig& config = {},
                           const std::vector<int>& sweep_of = {});

}  // namespace pitchlab::mapping
