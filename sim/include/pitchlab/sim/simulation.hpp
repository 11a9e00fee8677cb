#pragma once
// One MuJoCo world with the P3 robot: owns mjModel/mjData, steps physics, runs the robot's
// low-level servos (pitch gravity feed-forward, hooks for the base controller), gives ground truth.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sim/robot_model.hpp"
#include "pitchlab/sim/world.hpp"

struct mjModel_;
struct mjData_;

namespace pitchlab::sim {

/// How PlaceRobot finds and checks a start pose.
struct PlacementConfig {
  double drop_height_m = 0.01;  ///< start this far above the highest ground sample [m]
  double max_step_m = 0.05;     ///< support may vary this much under the footprint [m]
  double max_penetration_m =
      0.005;                       ///< contact depth with a non-ground geom that is a collision [m]
  double max_tilt_deg = 30.0;      ///< settled roll/pitch beyond this is a failure [deg]
  double settle_speed_mps = 0.01;  ///< settled: linear speed below [m/s]
  double settle_rate_rps = 0.05;   ///< settled: angular speed below [rad/s]
  double settle_hold_s = 0.1;      ///< ... for this long [s]
  double max_settle_s = 3.0;       ///< give up after [s]
};

/// MuJoCo world + robot. Not copyable; one thread at a time.
class Simulation {
 public:
  /// Loads the world file and splices in the robot. Throws std::runtime_error naming the world
  /// path and MuJoCo's error text, or std::invalid_argument on a bad robot config.
  Simulation(const std::string& world_path, const RobotConfig& robot);
  /// From MJCF text (tests, generated worlds); relative files resolve against `base_dir`.
  static std::unique_ptr<Simulation> FromString(const std::string& world_xml,
                                                const std::string& base_dir,
                                                const RobotConfig& robot);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  const mjModel_* model() const;  ///< for the ray casters; valid for the Simulation's lifetime
  const mjData_* data() const;    ///< for the ray casters; valid for the Simulation's lifetime
  const RobotConfig& robot() const { return robot_; }
  const P3Params& params() const { return ParamsFor(robot_.model); }
  const WorldInfo& world() const { return world_; }
  const std::string& composed_xml() const { return composed_xml_; }  ///< what was loaded

  double time_s() const;      ///< simulated time [s]
  /// The physics step now: the world's <option timestep> (default 2 ms), or the robot's
  /// P3Params::locked_timestep_s while the laser is locked (Step says when) [s].
  double timestep_s() const;
  /// Advances `n` physics steps, running the pre/post step hooks around each. Before each, the
  /// laser locks on the base when its servo holds a fixed setpoint at rest and nothing is held
  /// (sim/README.md, Invariants): the pitch joint stops moving and the step becomes
  /// P3Params::locked_timestep_s. SetPitchSetpoint with a new setpoint or a rate, and HoldStill,
  /// unlock it.
  void Step(int n = 1);
  /// Steps until simulated time is within half a step of now + duration (at least one step when
  /// duration > 0; the step may change on the way) [s].
  void StepFor(double duration_s);

  Eigen::Isometry3d T_world_base() const;   ///< ground truth base_link pose
  Eigen::Isometry3d T_world_laser() const;  ///< ground truth laser (mirror) pose
  double pitch_rad() const;                 ///< true pitch joint angle [rad], + = nose down
  double pitch_rate_rps() const;            ///< [rad/s]
  /// Pitch servo setpoint [rad] and its rate [rad/s]; the servo adds gravity/bias and damping
  /// feed-forward, so it tracks a slewing setpoint and holds a fixed one exactly.
  void SetPitchSetpoint(double pitch_rad, double rate_rps = 0.0);
  double pitch_setpoint_rad() const { return pitch_setpoint_rad_; }
  /// Wheel velocity servo setpoints, left and right side [rad/s].
  void SetWheelSpeeds(double left_rps, double right_rps);
  /// For a robot standing still to scan: holds every joint but the pitch joint (the base, its
  /// wheels, a world's loose bodies) where it is. While held, each step keeps their positions and
  /// zero velocities, skips collision detection and the contact solve (most of a step's cost),
  /// and moves only the pitch joint, whose dynamics are then a fixed base's under gravity (the
  /// held joints weigh as if immovable). Holds nothing and returns false while a free body (the
  /// base, a loose box) still moves at 5 mm/s or turns at 0.01 rad/s, so what is still settling
  /// or sliding keeps its physics. Release puts the contact model and its solver's
  /// warm start back as they were.
  bool HoldStill();
  void Release();
  bool held() const;
  /// Mean wheel joint angle of the left / right side [rad] (the encoders' truth).
  Eigen::Vector2d WheelAngles() const;
  /// Mean wheel joint speed of the left / right side [rad/s].
  Eigen::Vector2d WheelSpeeds() const;
  /// True when a wheel motor is at its torque limit while turning slower than commanded.
  bool WheelStalled() const;
  /// Linear [m/s] and angular [rad/s] speed of the robot's root body.
  Eigen::Vector2d BaseSpeeds() const;

  /// Puts base_link at (x, y) with heading `yaw_rad` on the ground and lets it settle. Fails
  /// (kInvalidArgument) outside pitchlab:bounds, off the world (no ground under the footprint),
  /// inside or under an obstacle; (kFailed) when it does not settle or ends tilted.
  [[nodiscard]] Result<Eigen::Isometry3d> PlaceRobot(double x_m, double y_m, double yaw_rad,
                                                     const PlacementConfig& config = {});

  using StepHook = std::function<void()>;
  /// Registers hooks run before / after every physics step; returns an id for RemoveHooks.
  int AddStepHooks(StepHook before, StepHook after);
  void RemoveHooks(int id);

  /// MuJoCo warnings raised since the last call (mju_user_warning and mjData warning counters).
  std::vector<std::string> TakeWarnings();

 private:
  struct Impl;
  Simulation(const std::string& world_xml, const std::string& base_dir, const std::string& source,
             const RobotConfig& robot);

  RobotConfig robot_;
  WorldInfo world_;
  std::string composed_xml_;
  double pitch_setpoint_rad_ = 0.0;
  double pitch_setpoint_rate_rps_ = 0.0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pitchlab::sim
