#pragma once
// The simulated LMS200 behind the LineScanner seam: one ray per beam from the "robot_laser" site,
// cast by a sensors::RayCaster, turned into readings by sensors::Lms200Model.

#include <deque>
#include <memory>
#include <vector>

#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/ray_caster.hpp"
#include "pitchlab/sensors/scan_source.hpp"
#include "pitchlab/sensors/stopwatch.hpp"
#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

class SerialWorker;

/// LineScanner on a Simulation. `caster` and `sim` must outlive it; the caster must have been
/// built on sim.model()/sim.data() (it is Refresh()ed before every line cast at once; a
/// sweep casts on its own thread only with a static caster, whose Refresh does nothing).
class SimLineScanner final : public sensors::LineScanner {
 public:
  SimLineScanner(Simulation& sim, sensors::RayCaster& caster, const sensors::Lms200Config& config);
  /// Casts the line at the laser's current pose, stamps it with the sim time at its start and
  /// advances the simulation by line_period_s(). kTimeout when the period exceeds `timeout`.
  [[nodiscard]] Result<sensors::LaserLine> NextLine(std::chrono::milliseconds timeout) override;
  /// In a sweep, with a static caster (RayCaster::Static) and a second core, a line's rays are
  /// cast and its readings made on a thread of the scanner's own while the physics steps on
  /// through the line and the pitch axis's next move: the same readings, in the same order, as
  /// line by line. EndSweep rethrows what the casting threw.
  void BeginSweep() override;
  void EndSweep(std::vector<sensors::LaserLine>* lines) override;
  ~SimLineScanner() override;
  const sensors::Lms200Model& model() const { return model_; }
  /// Casts an interlaced line's sweeps (a line finer than 1 deg) each `lag_rad` further down
  /// than the one before (sensors::PitchUnitConfig::sweep_lag_deg); 0, the default, casts a line
  /// at one pitch. Throws std::invalid_argument when negative or not finite.
  void set_sweep_lag_rad(double lag_rad);
  /// Rays reach this far: 5 % beyond the range mode's maximum, so over-range can be flagged [m].
  float cast_range_m() const;
  /// Time spent so far making lines: casting their rays and turning ranges into readings (for a
  /// run's stage breakdown). CPU: all of it. Wall: the time the simulation's thread spent on it or
  /// waiting for it, i.e. not what overlapped the physics of a sweep.
  const sensors::Elapsed& line_time() const { return line_time_; }

 private:
  // Casts the line at T_world_laser and turns its ranges into readings (`line`'s stamp and pitch
  // left for the caller).
  void MakeLine(const Eigen::Isometry3d& T_world_laser, sensors::LaserLine& line);
  // Casts every beam of the line (ranges, and the edge and incidence rays the model asks for)
  // at T_world_laser.
  void CastBeams(const Eigen::Isometry3d& T_world_laser);
  void CastAt(const Eigen::Isometry3d& T_world_laser, double offset_rad, std::vector<float>& out,
              double tip_rad = 0.0);
  void CastIncidence(const Eigen::Isometry3d& T_world_laser);
  const std::vector<Eigen::Vector3d>& BeamDirections(double offset_rad, double tip_rad);

  // One set of beam directions in the laser frame (BeamDirections).
  struct BeamSet {
    double offset_rad, tip_rad;
    std::vector<Eigen::Vector3d> laser;
  };

  Simulation& sim_;
  sensors::RayCaster& caster_;
  sensors::Lms200Model model_;
  std::vector<float> origins_, directions_, ranges_, edge_lo_, edge_hi_, along_, across_,
      along_back_, across_back_, cos_incidence_;
  sensors::Elapsed line_time_;
  std::deque<BeamSet> beam_sets_;  // a deque: a set's reference stays valid as others are added
  // The sweep's casting thread (started by the first sweep that can use it) and the lines it
  // makes, in NextLine's order; in_sweep_: between BeginSweep and EndSweep with the thread on.
  std::unique_ptr<SerialWorker> worker_;
  std::deque<sensors::LaserLine> swept_;
  bool in_sweep_ = false;
  double sweep_cpu0_s_ = 0;  // the worker's CPU time when the sweep began [s]
  int sweeps_ = 1;           // interlaced sweeps in a line (sensors::InterlacedSweeps)
  double sweep_lag_rad_ = 0;  // set_sweep_lag_rad
  // MakeLine with a sweep lag: the line's casts so far, one interlaced sweep at a time.
  std::vector<float> line_ranges_, line_lo_, line_hi_, line_cos_;
};

}  // namespace pitchlab::sim
