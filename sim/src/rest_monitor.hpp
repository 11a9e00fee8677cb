#pragma once
// Private: decides from the base's recent poses whether a parked robot is at rest, so that
// Simulation may hold its state (see RestConfig).

#include <Eigen/Geometry>

#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

/// Compares the base's mean pose over consecutive windows of RestConfig::window_s: the mean
/// averages out the contact vibration each pitch step excites, so what is left is the drift (a
/// creep down a slope, a settling suspension) that a held state would lose.
class RestMonitor {
 public:
  explicit RestMonitor(const RestConfig& config) : config_(config) {}
  /// Forgets every window (the robot was moved, driven, or the state was held).
  void Reset();
  /// Adds the base pose and its instantaneous (linear [m/s], angular [rad/s]) speeds at `t_s`;
  /// true when the window just closed and its mean pose drifted from the previous window's by
  /// less than max_speed_mps / max_rate_rps, and the base is still by Stop()'s standard now.
  bool Add(double t_s, const Eigen::Isometry3d& T_world_base, const Eigen::Vector2d& speeds);

 private:
  RestConfig config_;
  bool have_ref_ = false, have_previous_ = false;
  Eigen::Isometry3d T_ref_ = Eigen::Isometry3d::Identity();  // poses are taken relative to it
  double window_start_s_ = 0.0;
  int count_ = 0;
  Eigen::Vector3d sum_position_ = Eigen::Vector3d::Zero(), sum_rotation_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_position_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_rotation_ = Eigen::Vector3d::Zero();
};

}  // namespace pitchlab::sim
