#include "pitchlab/mission/path_follower.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pitchlab::mission {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

void PurePursuitConfig::Validate() const {
  auto positive = [](const char* name, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      std::ostringstream os;
      os << "follower." << name << " = " << v << " must be a positive number";
      throw std::invalid_argument(os.str());
    }
  };
  positive("lookahead_m", lookahead_m);
  positive("max_speed_mps", max_speed_mps);
  positive("max_yaw_rate_rps", max_yaw_rate_rps);
  positive("max_decel_mps2", max_decel_mps2);
  positive("turn_in_place_rad", turn_in_place_rad);
  positive("goal_tolerance_m", goal_tolerance_m);
}

PurePursuit::PurePursuit(std::vector<Eigen::Vector2d> path, const PurePursuitConfig& config)
    : path_(std::move(path)), config_(config) {
  config_.Validate();
  if (path_.empty()) throw std::invalid_argument("pure pursuit: the path has no points");
  arc_m_.resize(path_.size(), 0.0);
  for (std::size_t i = 1; i < path_.size(); ++i) {
    arc_m_[i] = arc_m_[i - 1] + (path_[i] - path_[i - 1]).norm();
  }
  remaining_m_ = arc_m_.back();
}

Eigen::Vector2d PurePursuit::PointAt(double arc_m) const {
  if (arc_m <= 0.0) return path_.front();
  if (arc_m >= arc_m_.back()) return path_.back();
  const auto it = std::upper_bound(arc_m_.begin(), arc_m_.end(), arc_m);
  const std::size_t i = static_cast<std::size_t>(it - arc_m_.begin());  // arc_m_[i-1] <= arc
  const double seg = arc_m_[i] - arc_m_[i - 1];
  const double t = seg > 0.0 ? (arc_m - arc_m_[i - 1]) / seg : 0.0;
  return path_[i - 1] + t * (path_[i] - path_[i - 1]);
}

// Arc length of the path point closest to p, searched in [from, from + window] so that a path
// passing near itself does not make the robot jump ahead or back.
double PurePursuit::ClosestArc(const Eigen::Vector2d& p, double from_arc_m, double window_m) const {
  double best_arc = from_arc_m, best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < path_.size(); ++i) {
    if (arc_m_[i] < from_arc_m || arc_m_[i - 1] > from_arc_m + window_m) continue;
    const Eigen::Vector2d a = path_[i - 1], ab = path_[i] - path_[i - 1];
    const double len2 = ab.squaredNorm();
    double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double arc = arc_m_[i - 1] + t * std::sqrt(len2);
    if (arc < from_arc_m) t = 0.0;  // never behind the progress made
    const double d2 = (a + t * ab - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best_arc = std::max(arc, from_arc_m);
    }
  }
  return best_arc;
}

DriveCommand PurePursuit::Command(double x_m, double y_m, double yaw_rad) {
  const Eigen::Vector2d p(x_m, y_m);
  progress_m_ = ClosestArc(p, progress_m_, 2.0 * config_.lookahead_m + 1.0);
  remaining_m_ = arc_m_.back() - progress_m_;
  const double to_goal_m = (path_.back() - p).norm();
  if (to_goal_m < config_.goal_tolerance_m ||
      (remaining_m_ < config_.goal_tolerance_m && to_goal_m < 2 * config_.goal_tolerance_m)) {
    return {0.0, 0.0, true};
  }
  // Steer at the point one lookahead ahead (the goal itself near the end).
  const Eigen::Vector2d target = PointAt(progress_m_ + config_.lookahead_m);
  const Eigen::Vector2d d = target - p;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  double dx = c * d.x() + s * d.y(), dy = -s * d.x() + c * d.y();  // in the robot frame
  if (direction_ == 0) {
    direction_ =
        config_.reverse && std::abs(std::atan2(dy, dx)) > kPi - config_.turn_in_place_rad ? -1 : 1;
  }
  // Reversing, the robot is a unicycle heading yaw + pi whose forward speed is -v: steer that one.
  dx *= direction_;
  dy *= direction_;
  const double heading_error = std::atan2(dy, dx);
  DriveCommand cmd;
  if (std::abs(heading_error) > config_.turn_in_place_rad) {
    cmd.omega_rps = std::copysign(config_.max_yaw_rate_rps, heading_error);
    return cmd;
  }
  const double l2 = std::max(d.squaredNorm(), 1e-6);
  const double curvature = 2.0 * dy / l2;  // the arc through the robot and the target
  double v = config_.max_speed_mps;
  v = std::min(v, std::sqrt(2.0 * config_.max_decel_mps2 * std::max(to_goal_m, 0.0)));
  if (std::abs(curvature) > 1e-9) v = std::min(v, config_.max_yaw_rate_rps / std::abs(curvature));
  // Slow while the heading is off, so the robot turns onto the path before it runs.
  v *= std::max(0.0, std::cos(heading_error));
  cmd.v_mps = direction_ * v;
  cmd.omega_rps = std::clamp(v * curvature, -config_.max_yaw_rate_rps, config_.max_yaw_rate_rps);
  return cmd;
}

}  // namespace pitchlab::mission
