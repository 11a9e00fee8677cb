#pragma once
// The sim/hw seam for the laser: what the simulated LMS200 + servo and the serial drivers implement.
// A runtime choice made once at start-up, called once per line: virtual interfaces are right here.

#include <chrono>
#include <vector>

#include "pitchlab/sensors/laser_line.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::sensors {

/// A 2D line scanner (LMS200). Implemented by the simulator and by the serial driver.
class LineScanner {
 public:
  virtual ~LineScanner() = default;
  /// Next full sweep at the scanner's current pitch (pitch_rad left 0: the caller fills it from
  /// the encoder), or an error (timeout, device fault) after `timeout`.
  [[nodiscard]] virtual Result<LaserLine> NextLine(std::chrono::milliseconds timeout) = 0;
  /// A sweep: lines whose readings may be made after NextLine returns them (the simulator casts a
  /// line's rays on another core while its physics steps on). Between BeginSweep and EndSweep a
  /// line from NextLine may hold only its stamp_s; EndSweep(&lines) completes the sweep's lines,
  /// which `lines` holds in NextLine's order (the pitch_rad the caller set is kept), and
  /// EndSweep(nullptr) drops them (a failed scan) and must not throw. Every BeginSweep is ended, on every way out.
  /// A scanner that makes each line at once (the serial driver) keeps these defaults.
  virtual void BeginSweep() {}
  virtual void EndSweep(std::vector<LaserLine>* lines) { (void)lines; }
};

/// The pitching mount: a position-controlled servo with an encoder.
class PitchAxis {
 public:
  virtual ~PitchAxis() = default;
  /// Moves to the servo step nearest `pitch_rad`, waits until it has settled, and returns the
  /// encoder angle actually reached [rad]; an error on timeout or device fault.
  [[nodiscard]] virtual Result<double> MoveTo(double pitch_rad, std::chrono::milliseconds timeout) = 0;
  /// Current encoder angle [rad].
  [[nodiscard]] virtual Result<double> ReadEncoder() = 0;
};

}  // namespace pitchlab::sensors
