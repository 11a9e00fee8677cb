#pragma once
// Private: the MuJoCo side of Simulation, shared by simulation.cpp and placement.cpp.

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <mujoco/mujoco.h>

#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

struct Simulation::Impl {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  int robot_body = -1, root_qpos = -1, root_dof = -1;
  int base_site = -1, laser_site = -1;
  int pitch_qpos = -1, pitch_dof = -1, pitch_act = -1;
  struct Wheel {
    int qpos, dof, act;
    bool left;
  };
  std::vector<Wheel> wheels;
  // Joints made immovable: each keeps the position it had, at rest, its dofs' armature raised
  // so far that the rest of the model cannot move them within a step (Keep puts back what moved).
  struct HeldJoints {
    std::vector<std::pair<int, int>> joints;  // (qpos address, position count)
    std::vector<int> dofs;
    std::vector<mjtNum> qpos, armature;  // held positions; the dofs' own armature
    void Add(const mjModel* m, const mjData* d, int joint, int nq, int nv);
    void Freeze(mjModel* m);             // raises the armature, saving it
    void Keep(mjData* d) const;          // the held positions, zero velocity
    void Restore(mjModel* m) const;      // the dofs' own armature back
  };
  // Simulation::HoldStill's saved state: every joint but the pitch joint held, the solver's warm
  // start and the disable flags.
  struct Hold {
    HeldJoints held;
    std::vector<mjtNum> qacc_warmstart;
    int disableflags = 0;
  };
  std::optional<Hold> hold;
  // The laser locked on the base while its servo holds a fixed setpoint (Simulation::Step says
  // why): the pitch joint held.
  std::optional<HeldJoints> pitch_lock;
  double world_timestep_s = 0.0;  // the world's step: the pitch servo's, scanning
  double locked_timestep_s = 0.0;  // the step while the laser is locked (driving)
  void LockPitch();
  void UnlockPitch();
  std::map<int, std::pair<StepHook, StepHook>> hooks;
  int next_hook = 0;

  ~Impl() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
  bool InRobot(int body) const {
    for (int b = body; b > 0; b = m->body_parentid[b]) {
      if (b == robot_body) return true;
    }
    return false;
  }
  bool IsTerrain(int geom) const {
    return m->geom_type[geom] == mjGEOM_PLANE || m->geom_type[geom] == mjGEOM_HFIELD;
  }
  std::string GeomName(int geom) const {
    const char* name = mj_id2name(m, mjOBJ_GEOM, geom);
    return name ? std::string("'") + name + "'" : "#" + std::to_string(geom);
  }
};

}  // namespace pitchlab::sim
