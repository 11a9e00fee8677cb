#pragma once
// One MuJoCo world with the P3 robot: owns mjModel/mjData, steps physics, runs the robot's
// low-level servos (pitch gravity feed-forward, hooks for the base controller), gives ground truth.

#include <cmath>
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

/// When a parked robot counts as at rest. At rest the Simulation holds the MuJoCo state and
/// advances only time and the laser's pitch joint (a one-joint model on the held base) instead of
/// solving the whole robot and its contacts every step: 62 % of a mission's simulated time is
/// spent standing to scan. Thresholds are for the seed scan (17 s of sweep, see below).
struct RestConfig {
  bool enabled = true;  ///< false: every step solves the whole robot
  /// The base's mean pose is compared over consecutive windows this long [s]: each pitch step
  /// (25 lines/s) rings the tyre contacts at 1-15 mm/s and 1-100 mrad/s with micrometre
  /// amplitudes; five line periods average that out, leaving the drift.
  double window_s = 0.2;
  /// Mean drift below this is rest [m/s]: 1 mm over a 17 s sweep, less than an encoder tick
  /// (1.35 mm) and a fifth of the LMS200's range sigma (5 mm). A 10 deg slope's creep under
  /// the wheel hold (0.4 mm/s) is 6x above it and stays fully simulated.
  double max_speed_mps = 6e-5;
  /// Mean turn rate below this is rest [rad/s]: a fifth of the gyro's angle random walk over a
  /// 17 s sweep (0.02 deg/s/sqrt(Hz): 1.4 mrad), i.e. 0.3 mrad, 3 mm at 10 m.
  double max_rate_rps = 1.7e-5;
  /// ... and the base still by SimBase::Stop()'s standard at that instant [m/s], [rad/s].
  double still_speed_mps = 0.005;
  double still_rate_rps = 0.01;
  /// The held state is checked again by the whole model once the laser has pitched this far
  /// [rad]: 20 deg moves the LMS200's centre of mass (5 cm off the axis) by 1.7 cm and the
  /// robot's by 3 mm, 2.5 % of the load between front and rear tyres, enough to change a creep.
  double recheck_pitch_rad = 20.0 * M_PI / 180.0;

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
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
  double timestep_s() const;  ///< physics step (the world's <option timestep>, default 2 ms) [s]
  /// Advances `n` physics steps, running the pre/post step hooks around each.
  void Step(int n = 1);
  /// Advances round(duration / timestep) steps (at least one when duration > 0) [s].
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
  /// Mean wheel joint angle of the left / right side [rad] (the encoders' truth).
  Eigen::Vector2d WheelAngles() const;
  /// Mean wheel joint speed of the left / right side [rad/s].
  Eigen::Vector2d WheelSpeeds() const;
  /// True when a wheel motor is at its torque limit while turning slower than commanded.
  bool WheelStalled() const;
  /// Linear [m/s] and angular [rad/s] speed of the robot's root body.
  Eigen::Vector2d BaseSpeeds() const;

  /// Sets when the robot counts as at rest (validates; throws std::invalid_argument).
  void set_rest_config(const RestConfig& config);
  const RestConfig& rest_config() const { return rest_; }
  /// The base controller's word that the wheels are commanded zero (parked); the state is only
  /// held while it stands. Called before each step by SimBase; false releases a held state now.
  void PermitRest(bool parked);
  /// True while the state is held (only time and the pitch joint advance).
  bool resting() const;
  /// Simulated time spent with the state held since construction [s].
  double rest_time_s() const;

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
  RestConfig rest_;
  std::unique_ptr<Impl> impl_;

  double PitchServoCtrl(double bias_nm, double passive_nm) const;
  void StepPitchOnly();
  void UpdateRest();
};

}  // namespace pitchlab::sim
