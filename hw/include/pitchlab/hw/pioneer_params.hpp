#pragma once
// The conversion factors of the Pioneer P3 family, per robot subclass (the SYNC2 reply's third
// string), as ARIA's robot parameter files define them (params/<subclass>.p, the same numbers
// as ARIA's built-in ArRobotTypes and ROS p2os's robot_params). A SIP reports positions,
// heading and wheel speeds in these robot units; commands (VEL, RVEL) are mm/s and deg/s.

#include <string>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::hw {

/// One model's factors.
struct PioneerParams {
  std::string subclass;            ///< lower case, e.g. "p3at-sh"
  double angle_conv_rad = 0.0;     ///< AngleConvFactor: THPOS unit [rad] (2 pi / 4096)
  double dist_conv_mm = 0.0;       ///< DistConvFactor: XPOS / YPOS unit [mm]
  double vel_conv_mmps = 0.0;      ///< VelConvFactor: L/RVEL unit [mm/s]
  double vel2_divisor_mmps = 0.0;  ///< Vel2Divisor: VEL2 wheel-speed unit [mm/s]
};

/// The factors of `subclass` (matched without regard to case, as ARIA does); kInvalidArgument
/// naming the subclass and the known ones when it is not a P3-family model.
[[nodiscard]] Result<PioneerParams> FindPioneerParams(const std::string& subclass);

}  // namespace pitchlab::hw
