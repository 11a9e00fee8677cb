#pragma once
// The simulated P3 base behind the MobileBase seam: (v, omega) -> wheel servos with the P3
// firmware's speed and acceleration limits, and wheel-encoder odometry with seeded errors.

#include <cstdint>
#include <deque>
#include <random>

#include "pitchlab/sensors/mobile_base.hpp"
#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

/// Wheel-encoder odometry model. All errors off by default; the same seed gives the same bytes.
struct OdometryConfig {
  std::uint64_t seed = 1;        ///< noise seed
  int ticks_per_rev = 500;       ///< encoder ticks per wheel revolution [1]
  double scale_sigma = 0.0;      ///< per-side wheel radius scale error, drawn once [1]
  double increment_sigma = 0.0;  ///< relative Gaussian noise on each wheel increment [1]
  /// Relative error of the track the odometry assumes (skid-steer slip / ICR mismatch) [1].
  double track_error = 0.0;
  double update_period_s = 0.01;  ///< odometry integration period [s]
  double speed_window_s = 0.1;    ///< v and omega are averaged over this (P3 SIP: 10 Hz) [s]
  /// Heading from a yaw-rate gyro instead of the wheels (the P3's gyro-corrected odometry):
  /// skid-steer wheel odometry misjudges turns by ~10 % on rough ground.
  bool gyro = true;
  double gyro_bias_dps = 0.01;        ///< constant yaw-rate bias [deg/s]
  double gyro_noise_dps_rthz = 0.02;  ///< white yaw-rate noise density [deg/s/sqrt(Hz)]

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// MobileBase on a Simulation. The base keeps its last command (like the P3 firmware) while
/// anything steps the simulation; odometry integrates on every step. `sim` must outlive it.
class SimBase final : public sensors::MobileBase {
 public:
  SimBase(Simulation& sim, const OdometryConfig& odometry = {});  ///< validates; throws
  ~SimBase() override;
  SimBase(const SimBase&) = delete;
  SimBase& operator=(const SimBase&) = delete;

  /// Commands (v [m/s], omega [rad/s]), clamped to the P3's limits and ramped at its acceleration
  /// limits, and steps the simulation `duration_s` [s]. kInvalidArgument on non-finite input.
  [[nodiscard]] Result<sensors::Odometry> Drive(double v_mps, double omega_rps,
                                                double duration_s) override;
  [[nodiscard]] Result<sensors::Odometry> ReadOdometry() override;
  /// Stops without the acceleration ramp, as the P3's E_STOP does ("overrides decel", ARIA's
  /// ArCommands): the wheels are held where they are, as hard as their motors can; the
  /// simulation is not stepped. The next Drive ramps from standstill.
  void EmergencyStop();
  /// Commands zero and steps until the base is still (kTimeout after `timeout_s` [s]).
  [[nodiscard]] Result<sensors::Odometry> Stop(double timeout_s = 3.0);
  /// Restarts odometry at the origin from the current wheel angles (after PlaceRobot).
  void ResetOdometry();
  /// Effective track used for (v, omega) <-> wheel speeds: geometric track x track_factor [m].
  double effective_track_m() const;
  /// The ramped command currently applied: (v [m/s], omega [rad/s]).
  Eigen::Vector2d command() const { return command_; }

 private:
  void BeforeStep();
  void AfterStep();
  void IntegrateOdometry();

  Simulation& sim_;
  OdometryConfig config_;
  int hooks_ = -1;
  Eigen::Vector2d target_ = Eigen::Vector2d::Zero();        // (v, omega) commanded
  Eigen::Vector2d command_ = Eigen::Vector2d::Zero();       // after the acceleration ramp
  Eigen::Vector2d integral_rps_ = Eigen::Vector2d::Zero();  // wheel PI integral, per side
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Vector2d scale_ = Eigen::Vector2d::Ones();  // per-side radius error
  Eigen::Vector2d last_ticks_ = Eigen::Vector2d::Zero();
  double since_update_s_ = 0.0;
  double last_true_yaw_rad_ = 0.0;  // what the gyro integrates
  bool holding_ = false;            // parked: wheels held at hold_angles_
  Eigen::Vector2d hold_angles_ = Eigen::Vector2d::Zero();
  sensors::Odometry odometry_;
  struct Increment {
    double dt_s, distance_m, yaw_rad;
  };
  std::deque<Increment> window_;  // recent increments for v and omega
};

}  // namespace pitchlab::sim
