#pragma once
// The simulated pitch unit behind the PitchAxis seam: servo steps and encoder quantization from
// sensors::PitchUnitModel, motion from MuJoCo's position-controlled "robot_laser_pitch" joint.

#include "pitchlab/sensors/pitch_unit.hpp"
#include "pitchlab/sensors/scan_source.hpp"
#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

/// PitchAxis on a Simulation. `sim` must outlive it.
class SimPitchAxis final : public sensors::PitchAxis {
 public:
  SimPitchAxis(Simulation& sim, const sensors::PitchUnitConfig& config);  ///< validates; throws
  /// Slews the setpoint to the servo step nearest `pitch_rad` at the servo's speed, steps physics
  /// for the model's MoveTime and until the joint is within half an encoder count and still;
  /// returns the encoder angle [rad]. kTimeout when that takes longer than `timeout` (sim time).
  [[nodiscard]] Result<double> MoveTo(double pitch_rad, std::chrono::milliseconds timeout) override;
  /// Encoder angle of the true joint angle [rad].
  [[nodiscard]] Result<double> ReadEncoder() override;
  const sensors::PitchUnitModel& model() const { return model_; }

 private:
  Simulation& sim_;
  sensors::PitchUnitModel model_;
};

}  // namespace pitchlab::sim
