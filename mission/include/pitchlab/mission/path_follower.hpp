#pragma once
// Pure pursuit: the closed loop's path-following controller. A pure function of the pose estimate
// and the path, so the same code drives the simulated and the real P3 through sensors::MobileBase.

#include <vector>

#include <Eigen/Core>

namespace pitchlab::mission {

struct PurePursuitConfig {
  double lookahead_m = 0.45;       ///< distance along the path to the point steered at [m]
  double max_speed_mps = 0.5;      ///< cruise speed, clamped further by the base [m/s]
  double max_yaw_rate_rps = 1.0;   ///< [rad/s]
  double max_decel_mps2 = 0.4;     ///< slow down to stop at the path's end [m/s^2]
  double turn_in_place_rad = 1.2;  ///< heading error beyond which the robot turns on the spot [rad]
  double goal_tolerance_m = 0.15;  ///< the end is reached within this distance [m]
  /// A path that starts so far behind the robot that it would turn on the spot (heading error
  /// beyond pi - turn_in_place_rad) is followed in reverse instead, all the way. A skid-steer
  /// robot turning on the spot on a slope slides downhill (the simulated P3-AT: 0.12 m per quarter
  /// turn on 10 deg; terrain seeds 205 and 219 slid 0.3 m into a crack turning round on a 7 deg
  /// flank), and a plan that starts behind the robot is mostly the way back out of a place the
  /// last scan showed hemmed in. The ground behind is in the map the path was planned on.
  bool reverse = true;

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// One control step's output.
struct DriveCommand {
  double v_mps = 0.0;      ///< [m/s]
  double omega_rps = 0.0;  ///< [rad/s]
  bool done = false;       ///< the end of the path is within tolerance; the command is zero
};

/// Follows a polyline of (x, y) points [m]; keeps its progress so it never steers back to a part
/// of the path already passed.
class PurePursuit {
 public:
  /// Throws std::invalid_argument on an invalid config or a path of fewer than one point.
  PurePursuit(std::vector<Eigen::Vector2d> path, const PurePursuitConfig& config);

  /// Command for the robot at (x, y) [m] heading `yaw_rad` [rad] in the path's frame.
  DriveCommand Command(double x_m, double y_m, double yaw_rad);
  /// Path length not yet passed [m].
  double remaining_m() const { return remaining_m_; }
  /// True when the follower drives the path backwards (decided at the first command).
  bool reversing() const { return direction_ < 0; }

 private:
  std::vector<Eigen::Vector2d> path_;
  std::vector<double> arc_m_;  ///< arc length at each vertex [m]
  PurePursuitConfig config_;
  double progress_m_ = 0.0;  ///< arc length of the closest point so far [m]
  double remaining_m_ = 0.0;
  int direction_ = 0;  ///< +1 forwards, -1 in reverse, 0 before the first command

  Eigen::Vector2d PointAt(double arc_m) const;
  double ClosestArc(const Eigen::Vector2d& p, double from_arc_m, double window_m) const;
};

}  // namespace pitchlab::mission
