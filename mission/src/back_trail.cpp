#include "back_trail.hpp"

#include <stdexcept>

namespace pitchlab::mission {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kRetraceTolerance_m = 0.05;  // a retrace ends this close to the way's end
}  // namespace

BackTrail::BackTrail(double keep_m) : keep_m_(keep_m) {
  if (!(keep_m > 0)) throw std::invalid_argument("back trail: keep_m must be positive");
}

void BackTrail::Add(const Eigen::Vector2d& p) {
  if (!p.allFinite()) return;
  if (!points_.empty()) {
    const double step = (p - points_.back()).norm();
    if (step < kRetraceTolerance_m) return;
    length_m_ += step;
  }
  points_.push_back(p);
  // Drop the oldest points while what is left still spans keep_m.
  while (points_.size() > 2 && length_m_ - (points_[1] - points_[0]).norm() >= keep_m_) {
    length_m_ -= (points_[1] - points_[0]).norm();
    points_.pop_front();
  }
}

std::vector<Eigen::Vector2d> BackTrail::WayBack(const Eigen::Vector2d& here,
                                                double length_m) const {
  std::vector<Eigen::Vector2d> way{here};
  double arc = 0;
  for (auto it = points_.rbegin(); it != points_.rend() && arc < length_m; ++it) {
    const double step = (*it - way.back()).norm();
    if (step == 0) continue;
    if (arc + step > length_m) {  // the last piece cut at length_m
      way.push_back(way.back() + (*it - way.back()) * ((length_m - arc) / step));
      break;
    }
    arc += step;
    way.push_back(*it);
  }
  return way;
}

PurePursuitConfig RetraceFollower(double speed_mps, double yaw_rate_rps) {
  PurePursuitConfig follow;
  follow.lookahead_m = kMinRetrace_m;
  follow.max_speed_mps = speed_mps;
  follow.max_yaw_rate_rps = yaw_rate_rps;
  follow.goal_tolerance_m = kRetraceTolerance_m;
  follow.reverse = true;
  follow.turn_in_place_rad = kPi / 2;  // reversing picked for anything behind the axle
  follow.Validate();
  return follow;
}

double PolylineLength(const std::vector<Eigen::Vector2d>& points) {
  double length = 0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

}  // namespace pitchlab::mission
