#pragma once
// The robot's recent track, so that a back-off retraces the ground it has just driven over instead
// of reversing blind along its heading: after a turn, on a curve or on the spot, the heading's
// line behind the robot is ground it never drove (nor, behind the laser's view, saw close by).

#include <cstddef>
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mission/path_follower.hpp"

namespace pitchlab::mission {

/// A way back shorter than this is not worth retracing: reverse straight [m]. The retrace steers
/// at a point this far along the way (RetraceFollower), so a shorter one is a straight line.
inline constexpr double kMinRetrace_m = 0.3;

/// Positions the base passed through, in its odometry frame (continuous across stops, unlike the
/// map estimate that a registration moves), newest last: points as far apart as a retrace ends
/// from its end (a finer track would be followed no closer), about `keep_m` of track.
class BackTrail {
 public:
  /// Throws std::invalid_argument unless keep_m is positive.
  explicit BackTrail(double keep_m);

  void Add(const Eigen::Vector2d& p);
  /// The way back from `here`: `here`, then the track from the newest point to the oldest, cut at
  /// `length_m` of arc. Just `here` when the track is empty.
  std::vector<Eigen::Vector2d> WayBack(const Eigen::Vector2d& here, double length_m) const;
  std::size_t size() const { return points_.size(); }

 private:
  double keep_m_;
  std::deque<Eigen::Vector2d> points_;
  double length_m_ = 0;  // arc length over points_
};

/// The path follower that retraces a way back at `speed_mps`, turning at most `yaw_rate_rps`: in
/// reverse while the way lies behind the axle (forwards when it lies ahead, as after a turn on
/// the spot or for a robot that came in reverse), never turning on the spot (that slides a
/// skid-steer base on a slope: path_follower.hpp), steering at a point kMinRetrace_m ahead (the
/// trail's bends are those of the path follower's turns, on the scale of its 0.45 m lookahead).
PurePursuitConfig RetraceFollower(double speed_mps, double yaw_rate_rps);

/// Length of a polyline [m].
double PolylineLength(const std::vector<Eigen::Vector2d>& points);

}  // namespace pitchlab::mission
