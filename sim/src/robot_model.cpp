#include "pitchlab/sim/robot_model.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "robot_layout.hpp"

namespace pitchlab::sim {
namespace {

// Pioneer 3 operations manual (MobileRobots, 2006) and the ARIA parameter files.
P3Params MakeP3At() {
  P3Params p;
  p.name = "P3-AT";
  p.length_m = 0.508;
  p.width_m = 0.497;
  p.height_m = 0.277;
  p.base_mass_kg = 12.0;
  p.battery_x_m = -0.05;  // battery box behind the centre, loaded through the rear door
  p.wheels = 4;
  p.wheel_radius_m = 0.1075;  // 215 mm pneumatic tyres
  p.wheel_width_m = 0.095;
  p.wheel_mass_kg = 0.6;
  p.track_m = p.width_m - p.wheel_width_m;  // wheels flush with the overall width
  p.wheelbase_m = 0.268;
  p.chassis_bottom_m = 0.08;
  p.max_speed_mps = 0.7;
  p.max_yaw_rate_rps = 140.0 * M_PI / 180.0;
  p.max_accel_mps2 = 0.5;
  p.max_yaw_accel_rps2 = 100.0 * M_PI / 180.0;  // ARIA RotAccel default
  p.wheel_torque_nm = 12.0;
  p.wheel_kv = 10.0;
  p.wheel_armature_kgm2 = 0.02;
  // Driving with the laser locked (Simulation::Step): the tyres' contacts (solref 0.02 s, stable
  // to 10 ms) and the wheel servo, explicit in kv (kv * step / wheel inertia = 1.7 < 2 with a
  // wheel off the ground) allow 4 ms; the skid-steer turn, tip and creep tests hold at it.
  p.locked_timestep_s = 0.004;
  p.track_factor = 2.4;  // calibrated: commanded / true yaw rate, 0.3-1 rad/s (spread 2.3-2.6)
  return p;
}

P3Params MakeP3Dx() {
  P3Params p;
  p.name = "P3-DX";
  p.length_m = 0.455;
  p.width_m = 0.381;
  p.height_m = 0.237;
  p.base_mass_kg = 9.0;
  p.wheels = 2;
  p.wheel_radius_m = 0.0975;  // 195 mm solid rubber tyres
  p.wheel_width_m = 0.0475;
  p.wheel_mass_kg = 0.5;
  p.track_m = p.width_m - p.wheel_width_m;
  p.wheelbase_m = 0.0;
  p.chassis_bottom_m = 0.09;
  p.max_speed_mps = 1.2;
  p.max_yaw_rate_rps = 300.0 * M_PI / 180.0;
  p.max_accel_mps2 = 0.5;
  p.max_yaw_accel_rps2 = 100.0 * M_PI / 180.0;
  p.wheel_torque_nm = 12.0;
  p.wheel_kv = 8.0;
  p.wheel_armature_kgm2 = 0.02;
  // Its turn on the spot changes above 2.5 ms (SimBase's 90 deg turn test: 1.50 -> 1.38 rad):
  // the world's step throughout.
  p.locked_timestep_s = 0.002;
  p.track_factor = 1.0;
  p.footprint_x_m = -0.045;   // p2os_urdf: chassis centre 45 mm behind the axle
  p.chassis_com_x_m = p.footprint_x_m;
  p.battery_x_m = -0.09;  // batteries behind the axle keep the laser's weight off the nose
  p.caster_radius_m = 0.04;
  p.caster_x_m = -0.20;
  return p;
}

std::string Vec(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << std::setprecision(9) << v.x() << ' ' << v.y() << ' ' << v.z();
  return os.str();
}

std::string Quat(const Eigen::Quaterniond& q) {
  std::ostringstream os;
  os << std::setprecision(9) << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z();
  return os.str();
}

// Explicit inertials keep the robot independent of the world's <compiler inertiafromgeom>.
std::string BoxInertial(const Eigen::Vector3d& pos, double mass, const Eigen::Vector3d& size) {
  const Eigen::Vector3d s2 = size.cwiseProduct(size);
  const Eigen::Vector3d I(mass * (s2.y() + s2.z()) / 12, mass * (s2.x() + s2.z()) / 12,
                          mass * (s2.x() + s2.y()) / 12);
  return "<inertial pos=\"" + Vec(pos) + "\" mass=\"" + std::to_string(mass) + "\" diaginertia=\"" +
         Vec(I) + "\"/>";
}

const char* kWheelQuat = "0.70710678 -0.70710678 0 0";  // cylinder axis z -> y

void AppendWheel(std::ostringstream& os, const P3Params& p, const WheelSpec& w) {
  const double r = p.wheel_radius_m, h = p.wheel_width_m, m = p.wheel_mass_kg;
  const double I_axis = 0.5 * m * r * r, I_rim = m * (3 * r * r + h * h) / 12;
  os << "    <body name=\"" << w.body << "\" pos=\"" << Vec(w.pos_m) << "\">\n"
     << "      <inertial pos=\"0 0 0\" mass=\"" << m << "\" diaginertia=\"" << I_rim << ' '
     << I_axis << ' ' << I_rim << "\"/>\n"
     << "      <joint name=\"" << w.joint << "\" type=\"hinge\" axis=\"0 1 0\" armature=\""
     << p.wheel_armature_kgm2 << "\" damping=\"0.01\"/>\n"
     << "      <geom name=\"" << w.body << "_tyre\" type=\"cylinder\" size=\"" << r << ' ' << h / 2
     << "\" quat=\"" << kWheelQuat << "\" rgba=\"0.1 0.1 0.1 1\"/>\n"
     << "    </body>\n";
}

void AppendCaster(std::ostringstream& os, const P3Params& p) {
  const double r = p.caster_radius_m, m = 0.1;
  os << "    <body name=\"robot_caster\" pos=\"" << p.caster_x_m << " 0 " << r << "\">\n"
     << "      <inertial pos=\"0 0 0\" mass=\"" << m << "\" diaginertia=\"" << 0.4 * m * r * r
     << ' ' << 0.4 * m * r * r << ' ' << 0.4 * m * r * r << "\"/>\n"
     << "      <joint name=\"robot_caster_ball\" type=\"ball\" damping=\"0.001\"/>\n"
     << "      <geom name=\"robot_caster_ball\" type=\"sphere\" size=\"" << r
     << "\" rgba=\"0.2 0.2 0.2 1\"/>\n"
     << "    </body>\n";
}

// Rigidly attached (no joint): only their mass and inertia matter, not their shape.
void AppendBatteries(std::ostringstream& os, const P3Params& p) {
  const Eigen::Vector3d size(0.151, 3 * 0.065, 0.094);
  const Eigen::Vector3d pos(p.battery_x_m, 0, p.chassis_bottom_m + 0.005 + size.z() / 2);
  os << "    <body name=\"robot_batteries\" pos=\"" << Vec(pos) << "\">\n"
     << "      " << BoxInertial(Eigen::Vector3d::Zero(), p.battery_mass_kg, size) << "\n"
     << "    </body>\n";
}

// LMS200: 156 W x 155 D x 210 H mm, 4.5 kg; the box centre sits below the mirror centre.
void AppendLaser(std::ostringstream& os, const RobotConfig& c, const P3Params& p) {
  const Eigen::Vector3d box_size(0.155, 0.156, 0.210);
  const Eigen::Vector3d box_pos = c.mount.t_mount_laser_m - Eigen::Vector3d(0, 0, 0.04);
  const Eigen::Isometry3d T_mount_laser = c.mount.MountToLaser();
  const PitchServoConfig& s = c.pitch_servo;
  os << "    <body name=\"robot_laser_mount\" pos=\"" << Vec(c.mount.t_base_mount_m) << "\">\n"
     << "      " << BoxInertial(box_pos, p.laser_mass_kg, box_size) << "\n"
     << "      <joint name=\"" << kPitchJoint
     << "\" type=\"hinge\" axis=\"0 1 0\" damping=\"0.5\" armature=\"" << s.armature_kgm2
     << "\"/>\n"
     << "      <geom name=\"robot_lms200\" type=\"box\" size=\"" << Vec(box_size / 2) << "\" pos=\""
     << Vec(box_pos) << "\" rgba=\"0.2 0.3 0.8 1\"/>\n"
     << "      <site name=\"" << kLaserSite << "\" pos=\"" << Vec(T_mount_laser.translation())
     << "\" quat=\"" << Quat(Eigen::Quaterniond(T_mount_laser.rotation())) << "\"/>\n"
     << "    </body>\n";
}

// Two side plates from the top plate up to the pitch axis, either side of the LMS200.
void AppendBracket(std::ostringstream& os, const RobotConfig& c, const P3Params& p) {
  const Eigen::Vector3d& axis = c.mount.t_base_mount_m;
  const double h = axis.z() - p.height_m;
  if (h <= 0.0) return;
  for (int side : {-1, 1}) {
    const Eigen::Vector3d pos(axis.x(), side * 0.093, p.height_m + h / 2);
    os << "    <geom name=\"robot_bracket_" << (side < 0 ? "r" : "l") << "\" type=\"box\" size=\""
       << Vec(Eigen::Vector3d(0.03, 0.005, h / 2)) << "\" pos=\"" << Vec(pos)
       << "\" rgba=\"0.5 0.5 0.5 1\"/>\n";
  }
}

}  // namespace

void RobotConfig::Validate() const {
  auto invalid = [](const char* field, double value, const char* allowed) {
    std::ostringstream os;
    os << "robot." << field << " = " << value << " is invalid (" << allowed << ")";
    throw std::invalid_argument(os.str());
  };
  const P3Params& p = ParamsFor(model);
  if (!(mount.t_base_mount_m.z() > p.height_m)) {
    invalid("mount.t_base_mount_m.z", mount.t_base_mount_m.z(), "must be above the top plate");
  }
  if (!(std::abs(mount.t_base_mount_m.x()) < p.length_m / 2)) {
    invalid("mount.t_base_mount_m.x", mount.t_base_mount_m.x(), "within the footprint");
  }
  if (!(pitch_servo.kp_nm_per_rad > 0)) invalid("pitch_servo.kp", pitch_servo.kp_nm_per_rad, "> 0");
  if (!(pitch_servo.kv_nms_per_rad >= 0))
    invalid("pitch_servo.kv", pitch_servo.kv_nms_per_rad, ">= 0");
  if (!(pitch_servo.armature_kgm2 >= 0))
    invalid("pitch_servo.armature", pitch_servo.armature_kgm2, ">= 0");
  if (!(pitch_servo.max_torque_nm > 0))
    invalid("pitch_servo.max_torque", pitch_servo.max_torque_nm, "> 0");
  if (!(wheel_friction > 0 && wheel_friction <= 3))
    invalid("wheel_friction", wheel_friction, "0 < f <= 3");
}

const P3Params& ParamsFor(P3Model model) {
  static const P3Params at = MakeP3At(), dx = MakeP3Dx();
  return model == P3Model::kP3AT ? at : dx;
}

std::vector<WheelSpec> Wheels(const P3Params& p) {
  const double y = p.track_m / 2, z = p.wheel_radius_m, x = p.wheelbase_m / 2;
  if (p.wheels == 2) {
    return {{"robot_wheel_l", "robot_wheel_l", Eigen::Vector3d(0, y, z), true},
            {"robot_wheel_r", "robot_wheel_r", Eigen::Vector3d(0, -y, z), false}};
  }
  return {{"robot_wheel_fl", "robot_wheel_fl", Eigen::Vector3d(x, y, z), true},
          {"robot_wheel_rl", "robot_wheel_rl", Eigen::Vector3d(-x, y, z), true},
          {"robot_wheel_fr", "robot_wheel_fr", Eigen::Vector3d(x, -y, z), false},
          {"robot_wheel_rr", "robot_wheel_rr", Eigen::Vector3d(-x, -y, z), false}};
}

RobotMjcf MakeRobotMjcf(const RobotConfig& config) {
  config.Validate();
  const P3Params& p = ParamsFor(config.model);
  const std::vector<WheelSpec> wheels = Wheels(p);
  RobotMjcf out;

  std::ostringstream def;
  def << "<default>\n  <default class=\"" << kRobotDefaultClass << "\">\n"
      << "    <geom contype=\"1\" conaffinity=\"1\" condim=\"3\" friction=\""
      << config.wheel_friction << " 0.005 0.0001\" group=\"" << kRobotGeomGroup
      << "\" margin=\"0\" gap=\"0\" solref=\"0.02 1\" solimp=\"0.9 0.95 0.001\" priority=\"0\""
      << " density=\"0\"/>\n"
      << "    <joint limited=\"false\" stiffness=\"0\" frictionloss=\"0\" damping=\"0\""
      << " armature=\"0\"/>\n"
      << "    <site group=\"" << kRobotGeomGroup << "\" size=\"0.02\" rgba=\"1 0.5 0 1\"/>\n"
      << "    <general gear=\"1 0 0 0 0 0\" ctrllimited=\"false\" dyntype=\"none\"/>\n"
      << "  </default>\n</default>\n";
  out.defaults = def.str();

  // Chassis: from chassis_bottom to the top plate, between the wheels.
  const double chassis_w = p.track_m - p.wheel_width_m - 0.01;
  const double chassis_h = p.height_m - p.chassis_bottom_m;
  const Eigen::Vector3d chassis_size(p.length_m, chassis_w, chassis_h);
  const Eigen::Vector3d chassis_pos(p.footprint_x_m, 0, p.chassis_bottom_m + chassis_h / 2);
  const Eigen::Vector3d chassis_com(p.chassis_com_x_m, 0, chassis_pos.z());
  const double chassis_mass =
      p.base_mass_kg - p.wheels * p.wheel_mass_kg - (p.caster_radius_m > 0 ? 0.1 : 0.0);
  std::ostringstream body;
  body << std::setprecision(9);
  body << "<body name=\"" << kRobotBody << "\" childclass=\"" << kRobotDefaultClass
       << "\" pos=\"0 0 " << 0.01 << "\">\n"
       << "    <freejoint name=\"robot_root\"/>\n"
       << "    " << BoxInertial(chassis_com, chassis_mass, chassis_size) << "\n"
       << "    <site name=\"" << kBaseLinkSite << "\" pos=\"0 0 0\"/>\n"
       << "    <geom name=\"robot_chassis\" type=\"box\" size=\"" << Vec(chassis_size / 2)
       << "\" pos=\"" << Vec(chassis_pos) << "\" rgba=\"0.8 0.1 0.1 1\"/>\n";
  AppendBracket(body, config, p);
  AppendBatteries(body, p);
  for (const WheelSpec& w : wheels) AppendWheel(body, p, w);
  if (p.caster_radius_m > 0) AppendCaster(body, p);
  AppendLaser(body, config, p);
  body << "</body>\n";
  out.body = body.str();

  std::ostringstream act, sens;
  act << std::setprecision(9) << "<actuator>\n";
  sens << "<sensor>\n";
  for (const WheelSpec& w : wheels) {
    act << "  <velocity name=\"" << w.joint << "_motor\" class=\"" << kRobotDefaultClass
        << "\" joint=\"" << w.joint << "\" kv=\"" << p.wheel_kv
        << "\" forcelimited=\"true\" forcerange=\"" << -p.wheel_torque_nm << ' '
        << p.wheel_torque_nm << "\"/>\n";
    sens << "  <jointpos name=\"" << w.joint << "_encoder\" joint=\"" << w.joint << "\"/>\n";
  }
  const PitchServoConfig& s = config.pitch_servo;
  act << "  <general name=\"" << kPitchActuator << "\" class=\"" << kRobotDefaultClass
      << "\" joint=\"" << kPitchJoint << "\" gaintype=\"fixed\" gainprm=\"" << s.kp_nm_per_rad
      << "\" biastype=\"affine\" biasprm=\"0 " << -s.kp_nm_per_rad << ' ' << -s.kv_nms_per_rad
      << "\" forcelimited=\"true\" forcerange=\"" << -s.max_torque_nm << ' ' << s.max_torque_nm
      << "\"/>\n</actuator>\n";
  sens << "  <jointpos name=\"" << kPitchJoint << "_encoder\" joint=\"" << kPitchJoint << "\"/>\n"
       << "  <framepos name=\"robot_base_link_pos\" objtype=\"site\" objname=\"" << kBaseLinkSite
       << "\"/>\n</sensor>\n";
  out.actuators = act.str();
  out.sensors = sens.str();
  return out;
}

std::string RobotMjcfDocument(const RobotConfig& config) {
  const RobotMjcf r = MakeRobotMjcf(config);
  std::ostringstream os;
  os << "<mujoco model=\"pitchlab " << ParamsFor(config.model).name << "\">\n"
     << "<option timestep=\"0.002\"/>\n"
     << r.defaults << "<worldbody>\n"
     << "<light pos=\"0 0 5\" dir=\"0 0 -1\"/>\n"
     << "<geom name=\"floor\" type=\"plane\" size=\"10 10 0.1\"/>\n"
     << r.body << "</worldbody>\n"
     << r.actuators << r.sensors << "</mujoco>\n";
  return os.str();
}

}  // namespace pitchlab::sim
