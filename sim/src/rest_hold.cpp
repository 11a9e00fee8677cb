// Simulation's rest hold (RestConfig): a parked robot at rest keeps its MuJoCo state while only
// time and the laser's pitch joint advance, the joint on the held base as MuJoCo's own step
// would move it.

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <mujoco/mujoco.h>

#include "simulation_impl.hpp"

namespace pitchlab::sim {

void RestConfig::Validate() const {
  auto invalid = [](const char* field, double value, const char* allowed) {
    std::ostringstream os;
    os << "rest." << field << " = " << value << " is invalid (" << allowed << ")";
    throw std::invalid_argument(os.str());
  };
  if (!(window_s > 0 && window_s <= 10)) invalid("window_s", window_s, "0 < t <= 10");
  if (!(max_speed_mps > 0 && max_speed_mps <= 0.01)) {
    invalid("max_speed_mps", max_speed_mps, "0 < v <= 0.01");
  }
  if (!(max_rate_rps > 0 && max_rate_rps <= 0.01)) {
    invalid("max_rate_rps", max_rate_rps, "0 < w <= 0.01");
  }
  if (!(still_speed_mps > 0 && still_speed_mps <= 0.1)) {
    invalid("still_speed_mps", still_speed_mps, "0 < v <= 0.1");
  }
  if (!(still_rate_rps > 0 && still_rate_rps <= 0.1)) {
    invalid("still_rate_rps", still_rate_rps, "0 < w <= 0.1");
  }
  if (!(recheck_pitch_rad > 0 && recheck_pitch_rad <= M_PI)) {
    invalid("recheck_pitch_rad", recheck_pitch_rad, "0 < a <= pi");
  }
}

void Simulation::set_rest_config(const RestConfig& config) {
  config.Validate();
  rest_ = config;
  impl_->monitor = RestMonitor(rest_);
  impl_->held = false;
}

void Simulation::PermitRest(bool parked) {
  Impl& s = *impl_;
  s.permitted = parked;
  if (!parked && s.held) {
    s.held = false;
    s.monitor.Reset();
  }
}

bool Simulation::resting() const { return impl_->held; }
double Simulation::rest_time_s() const { return impl_->held_s; }

// One Euler step of the pitch joint alone, the base held: MuJoCo's mj_Euler for this one degree
// of freedom, (M + h b) qacc = actuator + passive - bias with the joint damping b implicit.
void Simulation::StepPitchOnly() {
  Impl& s = *impl_;
  const mjModel* m = s.m;
  mjData* d = s.d;
  const double h = m->opt.timestep;
  mj_kinematics(m, d);  // the laser's centre of mass and the axis at the current pitch
  const int body = m->jnt_bodyid[s.pitch_joint];
  const Eigen::Map<const Eigen::Vector3d> com(d->xipos + 3 * body);
  const Eigen::Map<const Eigen::Vector3d> anchor(d->xanchor + 3 * s.pitch_joint);
  const Eigen::Map<const Eigen::Vector3d> axis(d->xaxis + 3 * s.pitch_joint);
  const Eigen::Map<const Eigen::Vector3d> gravity(m->opt.gravity);
  // Gravity alone: about an axis at rest a turning body has no Coriolis or centrifugal torque.
  const double bias = -axis.dot((com - anchor).cross(m->body_mass[body] * gravity));
  const double q = d->qpos[s.pitch_qpos], qd = d->qvel[s.pitch_dof];
  const double damping = m->dof_damping[s.pitch_dof];
  const double passive = -damping * qd;  // the robot's joints have no stiffness or friction loss
  const int a = s.pitch_act;
  d->ctrl[a] = PitchServoCtrl(bias, passive);
  // The actuator as MuJoCo's: fixed gain, affine bias in length and velocity, force-limited.
  const mjtNum* gain = m->actuator_gainprm + mjNGAIN * a;
  const mjtNum* bias_prm = m->actuator_biasprm + mjNBIAS * a;
  double force = gain[0] * d->ctrl[a] + bias_prm[0] + bias_prm[1] * q + bias_prm[2] * qd;
  if (m->actuator_forcelimited[a]) {
    force = std::clamp(force, m->actuator_forcerange[2 * a], m->actuator_forcerange[2 * a + 1]);
  }
  d->actuator_force[a] = force;
  const double qacc = (force + passive - bias) / (s.pitch_inertia + h * damping);
  d->qvel[s.pitch_dof] = qd + h * qacc;
  d->qpos[s.pitch_qpos] = q + h * d->qvel[s.pitch_dof];
  d->time += h;
  s.held_s += h;
}

// After each step: release a held state once the laser has pitched far enough to change the
// load on the tyres; hold it once the monitor finds the parked base at rest.
void Simulation::UpdateRest() {
  Impl& s = *impl_;
  if (s.held) {
    if (std::abs(pitch_rad() - s.held_from_pitch_rad) >= rest_.recheck_pitch_rad) {
      s.held = false;
      s.monitor.Reset();
    }
    return;
  }
  // The one-joint step is MuJoCo's Euler step; a world with another integrator is always solved.
  if (!rest_.enabled || !s.permitted || s.placing || s.m->opt.integrator != mjINT_EULER) {
    s.monitor.Reset();
    return;
  }
  if (s.monitor.Add(time_s(), T_world_base(), BaseSpeeds())) {
    s.held = true;
    s.held_from_pitch_rad = pitch_rad();
    s.pitch_inertia = s.d->qM[s.m->dof_Madr[s.pitch_dof]];  // mj_crb's, armature included
    s.monitor.Reset();
  }
}

}  // namespace pitchlab::sim
