#include "rest_monitor.hpp"

namespace pitchlab::sim {

void RestMonitor::Reset() {
  have_ref_ = have_previous_ = false;
  count_ = 0;
  sum_position_.setZero();
  sum_rotation_.setZero();
}

bool RestMonitor::Add(double t_s, const Eigen::Isometry3d& T_world_base,
                      const Eigen::Vector2d& speeds) {
  if (!have_ref_) {
    T_ref_ = T_world_base;
    have_ref_ = true;
    window_start_s_ = t_s;
  }
  // Rotation vector relative to the reference: small rotations add like vectors.
  const Eigen::AngleAxisd turn(T_ref_.linear().transpose() * T_world_base.linear());
  sum_position_ += T_world_base.translation() - T_ref_.translation();
  sum_rotation_ += turn.angle() * turn.axis();
  ++count_;
  if (t_s - window_start_s_ < config_.window_s) return false;

  const Eigen::Vector3d position = sum_position_ / count_, rotation = sum_rotation_ / count_;
  const double span_s = t_s - window_start_s_;
  const bool at_rest = have_previous_ &&
                       (position - previous_position_).norm() < config_.max_speed_mps * span_s &&
                       (rotation - previous_rotation_).norm() < config_.max_rate_rps * span_s &&
                       speeds[0] < config_.still_speed_mps && speeds[1] < config_.still_rate_rps;
  previous_position_ = position;
  previous_rotation_ = rotation;
  have_previous_ = true;
  window_start_s_ = t_s;
  count_ = 0;
  sum_position_.setZero();
  sum_rotation_.setZero();
  return at_rest;
}

}  // namespace pitchlab::sim
