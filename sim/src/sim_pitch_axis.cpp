#include "pitchlab/sim/sim_pitch_axis.hpp"

#include <algorithm>
#include <cmath>

namespace pitchlab::sim {
namespace {

constexpr double kStillRate_rps = 0.01;  // settled: joint speed below this (0.6 deg/s) [rad/s]

}  // namespace

SimPitchAxis::SimPitchAxis(Simulation& sim, const sensors::PitchUnitConfig& config)
    : sim_(sim), model_(config) {}

Result<double> SimPitchAxis::MoveTo(double pitch_rad, std::chrono::milliseconds timeout) {
  if (!std::isfinite(pitch_rad)) return Fail(Error::Code::kInvalidArgument, "pitch is not finite");
  const double target = model_.StepAngle(model_.StepFor(pitch_rad));
  const double from = sim_.pitch_setpoint_rad();
  const double move_s = model_.MoveTime(from, target);
  const double speed_rps = model_.config().max_speed_dps * M_PI / 180.0;
  // Settled: still, and within one servo step. The encoder, not the setpoint, goes into Eq. 1, so
  // a steady-state error (gravity on a steeply tilted robot) costs nothing.
  const double tolerance = model_.config().step_deg * M_PI / 180.0;
  const double t0 = sim_.time_s(), timeout_s = timeout.count() / 1000.0;
  while (true) {
    // The servo's setpoint slews at its rated speed; MuJoCo's actuator follows.
    const double elapsed = sim_.time_s() - t0;
    const double travelled = std::min(std::abs(target - from), speed_rps * elapsed);
    const bool slewing = travelled < std::abs(target - from);
    // Once the slew is over the setpoint is the target itself: from + (target - from) need not
    // equal target in floating point.
    sim_.SetPitchSetpoint(slewing ? from + std::copysign(travelled, target - from) : target,
                          slewing ? std::copysign(speed_rps, target - from) : 0.0);
    const bool there = std::abs(sim_.pitch_rad() - target) < tolerance &&
                       std::abs(sim_.pitch_rate_rps()) < kStillRate_rps;
    if (elapsed >= move_s && there && sim_.pitch_setpoint_rad() == target) break;
    if (elapsed > timeout_s) {
      return Fail(Error::Code::kTimeout,
                  "pitch axis did not settle at " + std::to_string(target * 180.0 / M_PI) +
                      " deg within " + std::to_string(timeout.count()) + " ms (at " +
                      std::to_string(sim_.pitch_rad() * 180.0 / M_PI) + " deg)");
    }
    sim_.Step(1);
  }
  return model_.ReportedAngle(sim_.pitch_rad());
}

Result<double> SimPitchAxis::ReadEncoder() { return model_.ReportedAngle(sim_.pitch_rad()); }

}  // namespace pitchlab::sim
