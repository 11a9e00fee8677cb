#pragma once
// The whole simulated robot wired up: world + P3 + pitch axis + LMS200 + PitchingScanSource.
// An app does: SimRig rig(world, config); rig.PlaceAtDefaultStart(); rig.Acquire();

#include <memory>
#include <string>

#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/pitch_unit.hpp"
#include "pitchlab/sensors/pitching_scanner.hpp"
#include "pitchlab/sensors/ray_caster.hpp"
#include "pitchlab/sim/sim_base.hpp"
#include "pitchlab/sim/sim_imu.hpp"
#include "pitchlab/sim/sim_line_scanner.hpp"
#include "pitchlab/sim/sim_pitch_axis.hpp"
#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

/// Which ray caster the simulated LMS200 uses.
enum class CasterKind {
  kEmbree,  ///< fast (default)
  kMujoco,  ///< mj_ray reference
};

/// Everything a simulated run's hardware is built from.
struct SimRigConfig {
  RobotConfig robot;
  sensors::Lms200Config lms200;
  sensors::PitchUnitConfig pitch_unit;
  sensors::ScanPatternConfig pattern;
  OdometryConfig odometry;
  ImuConfig imu;  ///< deskews scans when imu.deskew
  PlacementConfig placement;
  CasterKind caster = CasterKind::kEmbree;
};

/// Simulation + SimBase + SimPitchAxis + SimLineScanner + PitchingScanSource. A ScanSource whose
/// scans carry the ground truth pose (has_truth, T_world_base).
class SimRig final : public sensors::ScanSource {
 public:
  /// Loads the world file. Throws (std::runtime_error / std::invalid_argument) naming the file,
  /// field and value on a bad world or config.
  SimRig(const std::string& world_path, const SimRigConfig& config);
  /// From MJCF text; relative files resolve against `base_dir`.
  static std::unique_ptr<SimRig> FromString(const std::string& world_xml,
                                            const std::string& base_dir,
                                            const SimRigConfig& config);
  ~SimRig() override;

  /// Places the robot (Simulation::PlaceRobot) and restarts odometry there.
  [[nodiscard]] Result<Eigen::Isometry3d> PlaceRobot(double x_m, double y_m, double yaw_rad);
  /// Places the robot at the world's pitchlab:default_start, else at (0, 0, 0).
  [[nodiscard]] Result<Eigen::Isometry3d> PlaceAtDefaultStart();
  /// Stops the base, then runs one pitch sweep, deskewed by the IMU when config.imu.deskew.
  /// T_world_base is the truth of the points' frame: when the scan started, or at its last line
  /// when deskewed.
  [[nodiscard]] Result<sensors::Scan3D> Acquire() override;

  Simulation& sim() { return *sim_; }
  SimBase& base() { return *base_; }
  SimPitchAxis& pitch_axis() { return *axis_; }
  SimLineScanner& scanner() { return *scanner_; }
  sensors::RayCaster& caster() { return *caster_; }
  sensors::PitchingScanSource& scan_source() { return *source_; }
  const SimRigConfig& config() const { return config_; }
  /// The scanner's true mount minus the nominal one (config().robot.mount), roll/pitch/yaw [rad]:
  /// drawn from config().lms200 (sensors::DrawMountErrorRpyRad); the scans are assembled with
  /// the nominal mount, so it shows in them as an uncalibrated scanner would.
  const Eigen::Vector3d& mount_error_rpy_rad() const { return mount_error_rpy_rad_; }

 private:
  SimRig(std::unique_ptr<Simulation> sim, const SimRigConfig& config);

  SimRigConfig config_;
  Eigen::Vector3d mount_error_rpy_rad_ = Eigen::Vector3d::Zero();
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<sensors::RayCaster> caster_;
  std::unique_ptr<SimBase> base_;
  std::unique_ptr<SimImu> imu_;
  std::unique_ptr<SimPitchAxis> axis_;
  std::unique_ptr<SimLineScanner> scanner_;
  std::unique_ptr<sensors::PitchingScanSource> source_;
};

}  // namespace pitchlab::sim
