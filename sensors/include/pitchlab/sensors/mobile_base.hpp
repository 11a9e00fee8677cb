#pragma once
// The sim/hw seam for the robot base: the MuJoCo P3 and the P2OS driver both implement it.

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::sensors {

/// Wheel odometry of a planar base, integrated since start-up in the `odom` frame.
struct Odometry {
  double stamp_s = 0.0;   ///< [s]
  double x_m = 0.0;       ///< [m]
  double y_m = 0.0;       ///< [m]
  double yaw_rad = 0.0;   ///< [rad]
  double v_mps = 0.0;     ///< forward speed [m/s]
  double omega_rps = 0.0; ///< yaw rate [rad/s]
  bool stalled = false;   ///< a motor reports stall

  /// The pose as T_odom_base (planar: z, roll, pitch are 0).
  Eigen::Isometry3d Pose() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translate(Eigen::Vector3d(x_m, y_m, 0.0));
    T.rotate(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()));
    return T;
  }
};

/// A differential / skid-steer base driven by (v, omega).
class MobileBase {
 public:
  virtual ~MobileBase() = default;
  /// Commands forward speed [m/s] and yaw rate [rad/s] (clamped to the base's limits) and holds
  /// them for `duration_s` [s]; returns the odometry at the end, or a device error.
  [[nodiscard]] virtual Result<Odometry> Drive(double v_mps, double omega_rps, double duration_s) = 0;
  /// Latest odometry without moving.
  [[nodiscard]] virtual Result<Odometry> ReadOdometry() = 0;
};

}  // namespace pitchlab::sensors
