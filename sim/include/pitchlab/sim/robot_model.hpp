#pragma once
// The simulated Pioneer P3 (AT skid-steer or DX differential) with a pitching LMS200, generated as
// MJCF text from a RobotConfig. Frames: base_link on the ground under the turning centre (the AT's
// footprint centre; the DX's wheel axle), x forward, y left, z up (REP-103); the pitch joint
// turns about base_link's y, positive = nose down.

#include <string>

#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sim {

/// MJCF names the simulator relies on. Everything but the root body carries the "robot_" prefix.
inline constexpr char kRobotBody[] = "robot";               ///< root body (has the freejoint)
inline constexpr char kBaseLinkSite[] = "robot_base_link";  ///< base_link frame
inline constexpr char kLaserSite[] = "robot_laser";         ///< laser frame (mirror centre)
inline constexpr char kPitchJoint[] = "robot_laser_pitch";  ///< hinge about y, + = nose down
inline constexpr char kPitchActuator[] = "robot_laser_pitch_servo";  ///< position actuator
inline constexpr char kRobotDefaultClass[] = "robot";  ///< childclass of every robot element
/// Robot geoms are in this geom group, so placement rays can skip them.
inline constexpr int kRobotGeomGroup = 3;

/// Which Pioneer 3.
enum class P3Model {
  kP3AT,  ///< 4-wheel skid-steer, outdoor
  kP3DX,  ///< 2-wheel differential with a rear caster, indoor
};

/// Pitch servo of the laser mount: a PD position actuator (MuJoCo <general>, affine bias) on the
/// hinge. Explicit in the velocity gain: needs kv * timestep / (armature + laser inertia) < 2.
struct PitchServoConfig {
  double kp_nm_per_rad = 4000.0;  ///< position gain: a stiff geared stepper drive [N m/rad]
  double kv_nms_per_rad = 34.0;   ///< velocity gain (damping ratio ~0.9) [N m s/rad]
  double armature_kgm2 = 0.05;    ///< reflected motor inertia of the gearbox [kg m^2]
  double max_torque_nm = 25.0;    ///< actuator torque limit [N m]
};

/// Everything the robot MJCF is generated from.
struct RobotConfig {
  P3Model model = P3Model::kP3AT;
  sensors::MountConfig mount;  ///< where the pitch axis and the mirror sit (also used by Eq. 1)
  PitchServoConfig pitch_servo;
  double wheel_friction = 1.0;  ///< rubber tyre sliding friction coefficient [1]

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// Physical parameters of one P3 variant (datasheet values; see sim/README.md).
struct P3Params {
  const char* name = "";
  double length_m = 0, width_m = 0, height_m = 0;  ///< overall, wheels included [m]
  double base_mass_kg = 0;  ///< body and wheels, without batteries and laser [kg]
  int wheels = 0;                                  ///< 4 (AT) or 2 (DX)
  double wheel_radius_m = 0;                       ///< [m]
  double wheel_width_m = 0;                        ///< [m]
  double wheel_mass_kg = 0;                        ///< each [kg]
  double track_m = 0;           ///< lateral distance between left and right wheel centres [m]
  double wheelbase_m = 0;       ///< front-rear axle distance, 0 for the DX [m]
  double chassis_bottom_m = 0;  ///< chassis underside above the ground [m]
  /// Footprint centre's x in base_link [m]: 0 for the AT; the DX's base_link is its wheel axle
  /// (the turning centre, as in p2os_urdf), 4.5 cm ahead of the footprint centre.
  double footprint_x_m = 0;
  double chassis_com_x_m = 0;      ///< chassis centre of mass x in base_link [m]
  double max_speed_mps = 0;        ///< [m/s]
  double max_yaw_rate_rps = 0;     ///< [rad/s]
  double max_accel_mps2 = 0;       ///< forward acceleration limit [m/s^2]
  double max_yaw_accel_rps2 = 0;   ///< yaw acceleration limit [rad/s^2]
  double wheel_torque_nm = 0;      ///< motor torque limit at the wheel [N m]
  double wheel_kv = 0;             ///< velocity servo gain [N m s/rad]
  double wheel_armature_kgm2 = 0;  ///< reflected gearbox inertia [kg m^2]
  /// Physics step while the laser is locked on the base (driving; Simulation::Step; the world's
  /// own step when it sets one) [s].
  double locked_timestep_s = 0.002;
  /// Effective track / geometric track: skid-steer turns need a wider virtual track (the ICR
  /// model of Mandow et al. 2007); 1.85 measured on this simulated P3-AT on a friction-1 floor
  /// over 0.3-2 rad/s (spread 1.8-2.0); 1 for the DX.
  double track_factor = 1;
  double caster_radius_m = 0;  ///< DX rear ball caster [m]
  double caster_x_m = 0;       ///< DX caster position [m]
  double laser_mass_kg = 4.5;  ///< LMS200 [kg]
  /// Three 12 V 7.2 Ah lead-acid batteries (2.4 kg each, 151 x 65 x 94 mm) side by side in the
  /// battery box on the chassis floor: the lowest, and with the laser the heaviest, load [kg].
  double battery_mass_kg = 3 * 2.4;
  double battery_x_m = 0;  ///< battery pack centre x in base_link [m]
};

/// Datasheet parameters of `model`.
const P3Params& ParamsFor(P3Model model);

/// The robot as MJCF fragments, ready to be spliced into a world.
struct RobotMjcf {
  std::string defaults;   ///< a top-level <default> holding <default class="robot">
  std::string body;       ///< the <body name="robot"> element for <worldbody>
  std::string actuators;  ///< an <actuator> section
  std::string sensors;    ///< a <sensor> section
};

/// Generates the robot's MJCF fragments. Throws std::invalid_argument on a bad config.
RobotMjcf MakeRobotMjcf(const RobotConfig& config);

/// A complete MJCF document of the robot on a flat floor, for inspection (`pitchlab sim dump`).
std::string RobotMjcfDocument(const RobotConfig& config);

}  // namespace pitchlab::sim
