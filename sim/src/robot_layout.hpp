#pragma once
// Private: the robot's wheel layout, shared by the MJCF generator and the simulation.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/sim/robot_model.hpp"

namespace pitchlab::sim {

/// One driven wheel: body and hinge names, centre in base_link [m], side.
struct WheelSpec {
  std::string body;
  std::string joint;
  Eigen::Vector3d pos_m;
  bool left = true;
};

/// The driven wheels of a P3 variant (left ones first).
std::vector<WheelSpec> Wheels(const P3Params& p);

}  // namespace pitchlab::sim
