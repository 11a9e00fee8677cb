#pragma once
// The perturbation registration's information and covariance are defined for: T <- Exp(omega, v) T
// in the target frame, Exp(omega, v) = [R(omega), v] (fast_pipeline.hpp), and its inverse Log.

#include <Eigen/Geometry>

namespace pitchlab::mapping {

/// [R(omega), v] for delta = (omega [rad], v [m]).
inline Eigen::Isometry3d Exp(const Eigen::Matrix<double, 6, 1>& delta) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = delta.head<3>();
  const double angle = w.norm();
  if (angle > 1e-12) T.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  T.translation() = delta.tail<3>();
  return T;
}

/// (angle-axis of R, t) of T: Exp's inverse.
inline Eigen::Matrix<double, 6, 1> Log(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  Eigen::Matrix<double, 6, 1> delta;
  delta << aa.angle() * aa.axis(), T.translation();
  return delta;
}

}  // namespace pitchlab::mapping
