#pragma once
// One planar sweep of a 2D laser at a known pitch: the unit the LMS200 (simulated or real) delivers.

#include <cstdint>
#include <vector>

namespace pitchlab::sensors {

/// Status of one reading. Only kValid readings carry a range; the others are never reported as 0 m.
enum class ReadingStatus : std::uint8_t {
  kValid = 0,
  kNoReturn = 1,   ///< nothing within the maximum range (LMS200 code 8191 in mm mode)
  kOverRange = 2,  ///< beyond the mode's maximum (LMS200 code 8183 in cm mode)
  kDazzled = 3,    ///< blinded (LMS200 code 8190); not produced by the simulator
};

/// One planar sweep at a known pitch. Readings are ordered by increasing beam angle.
struct LaserLine {
  double stamp_s = 0.0;              ///< time of the first beam [s]
  double duration_s = 0.0;           ///< time from the first to the last beam [s]
  double pitch_rad = 0.0;            ///< encoder pitch during the sweep [rad]
  double angle_min_rad = 0.0;        ///< beam angle of the first reading, 0 = straight ahead [rad]
  double angle_increment_rad = 0.0;  ///< angle between neighbouring readings [rad]
  std::vector<float> ranges_m;       ///< [m]; NaN where status is not kValid
  std::vector<ReadingStatus> status;  ///< one per reading

  /// Beam angle of reading i [rad].
  double Angle(std::size_t i) const { return angle_min_rad + angle_increment_rad * double(i); }
};

}  // namespace pitchlab::sensors
