#include "pitchlab/sim/sim_rig.hpp"

#include <array>
#include <cmath>

namespace pitchlab::sim {
namespace {

// The robot as built: the scanner sits on its mount turned by the run's drawn mount error (added
// to the nominal misalignment's roll, pitch and yaw). Only the simulation gets it; the scan source
// assembles with the nominal mount, as a pipeline that was never told would.
RobotConfig TrueRobot(const SimRigConfig& config) {
  RobotConfig robot = config.robot;
  const std::array<double, 3> e = sensors::DrawMountErrorRpyRad(config.lms200);
  robot.mount.misalignment_rpy_rad += Eigen::Vector3d(e[0], e[1], e[2]);
  return robot;
}

}  // namespace

SimRig::SimRig(const std::string& world_path, const SimRigConfig& config)
    : SimRig(std::make_unique<Simulation>(world_path, TrueRobot(config)), config) {}

std::unique_ptr<SimRig> SimRig::FromString(const std::string& world_xml,
                                           const std::string& base_dir,
                                           const SimRigConfig& config) {
  return std::unique_ptr<SimRig>(
      new SimRig(Simulation::FromString(world_xml, base_dir, TrueRobot(config)), config));
}

SimRig::SimRig(std::unique_ptr<Simulation> sim, const SimRigConfig& config)
    : config_(config), sim_(std::move(sim)) {
  const std::array<double, 3> e = sensors::DrawMountErrorRpyRad(config_.lms200);
  mount_error_rpy_rad_ = Eigen::Vector3d(e[0], e[1], e[2]);
  sensors::RayCasterOptions options;
  options.exclude_subtree_of_body = kRobotBody;
  caster_ = config_.caster == CasterKind::kEmbree
                ? sensors::MakeEmbreeRayCaster(sim_->model(), sim_->data(), options)
                : sensors::MakeMujocoRayCaster(sim_->model(), sim_->data(), options);
  base_ = std::make_unique<SimBase>(*sim_, config_.odometry);
  axis_ = std::make_unique<SimPitchAxis>(*sim_, config_.pitch_unit);
  scanner_ = std::make_unique<SimLineScanner>(*sim_, *caster_, config_.lms200);
  scanner_->set_sweep_lag_rad(config_.pitch_unit.sweep_lag_deg * M_PI / 180.0);
  source_ = std::make_unique<sensors::PitchingScanSource>(*scanner_, *axis_, config_.pattern,
                                                          config_.robot.mount);
  if (config_.imu.deskew) {
    imu_ = std::make_unique<SimImu>(*sim_, config_.imu);
    source_->set_attitude_probe(
        [this]() -> std::optional<Eigen::Quaterniond> { return imu_->Orientation(); },
        config_.imu.deskew_min_deg* M_PI / 180.0);
  }
}

SimRig::~SimRig() = default;

Result<Eigen::Isometry3d> SimRig::PlaceRobot(double x_m, double y_m, double yaw_rad) {
  Result<Eigen::Isometry3d> pose = sim_->PlaceRobot(x_m, y_m, yaw_rad, config_.placement);
  base_->ResetOdometry();
  return pose;
}

Result<Eigen::Isometry3d> SimRig::PlaceAtDefaultStart() {
  const Eigen::Vector3d start = sim_->world().default_start.value_or(Eigen::Vector3d::Zero());
  return PlaceRobot(start.x(), start.y(), start.z());
}

Result<sensors::Scan3D> SimRig::Acquire() {
  if (Result<sensors::Odometry> stopped = base_->Stop(); !stopped) {
    return Fail(stopped.error().code, "before the scan: " + stopped.error().message);
  }
  const Eigen::Isometry3d T_world_base = sim_->T_world_base();
  // Standing still only the pitch joint moves: the contact solve that kept the robot where it stood
  // was 90 % of a scan's physics (terrain seed 1: 0.54 s CPU per stop, held 0.05 s). Released on
  // every way out.
  struct Held {
    Simulation& sim;
    ~Held() { sim.Release(); }
  } held{*sim_};
  sim_->HoldStill();
  Result<sensors::Scan3D> scan = source_->Acquire();
  if (!scan) return scan;
  scan->has_truth = true;
  scan->T_world_base = scan->deskewed ? sim_->T_world_base() : T_world_base;
  return scan;
}

}  // namespace pitchlab::sim
