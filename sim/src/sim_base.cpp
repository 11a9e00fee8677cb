#include "pitchlab/sim/sim_base.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pitchlab::sim {
namespace {

constexpr double kWheelKi_per_s = 10.0;    // firmware PI: integral gain on wheel speed error
constexpr double kMaxIntegral_rps = 5.0;   // integral clamp [rad/s]
constexpr double kStillSpeed_mps = 0.005;  // Stop(): still below this [m/s]
constexpr double kStillRate_rps = 0.01;
constexpr double kHoldGain_per_s = 5.0;   // parked: wheel speed per radian off the held angle    // ... and this [rad/s]

double Ramp(double from, double to, double max_delta) {
  return from + std::clamp(to - from, -max_delta, max_delta);
}

Eigen::Vector2d Ticks(const Eigen::Vector2d& angles_rad, int ticks_per_rev) {
  const double tick_rad = 2.0 * M_PI / ticks_per_rev;
  return {std::floor(angles_rad[0] / tick_rad), std::floor(angles_rad[1] / tick_rad)};
}

}  // namespace

void OdometryConfig::Validate() const {
  auto invalid = [](const char* field, double value, const char* allowed) {
    std::ostringstream os;
    os << "odometry." << field << " = " << value << " is invalid (" << allowed << ")";
    throw std::invalid_argument(os.str());
  };
  if (ticks_per_rev < 1) invalid("ticks_per_rev", ticks_per_rev, ">= 1");
  if (!(scale_sigma >= 0 && scale_sigma < 0.5)) invalid("scale_sigma", scale_sigma, "0 <= s < 0.5");
  if (!(increment_sigma >= 0 && increment_sigma < 1)) {
    invalid("increment_sigma", increment_sigma, "0 <= s < 1");
  }
  if (!(track_error > -0.5 && track_error < 2)) invalid("track_error", track_error, "-0.5 < e < 2");
  if (!(gyro_bias_dps >= -10 && gyro_bias_dps <= 10)) invalid("gyro_bias_dps", gyro_bias_dps, "+-10");
  if (!(gyro_noise_dps_rthz >= 0 && gyro_noise_dps_rthz <= 10)) {
    invalid("gyro_noise_dps_rthz", gyro_noise_dps_rthz, "0 .. 10");
  }
  if (!(update_period_s > 0 && update_period_s <= 1)) {
    invalid("update_period_s", update_period_s, "0 < t <= 1");
  }
  if (!(speed_window_s >= update_period_s && speed_window_s <= 10)) {
    invalid("speed_window_s", speed_window_s, "update_period_s <= t <= 10");
  }
}

SimBase::SimBase(Simulation& sim, const OdometryConfig& odometry)
    : sim_(sim), config_(odometry), rng_(odometry.seed) {
  config_.Validate();
  scale_ = Eigen::Vector2d(1.0 + config_.scale_sigma * normal_(rng_),
                           1.0 + config_.scale_sigma * normal_(rng_));
  ResetOdometry();
  hooks_ = sim_.AddStepHooks([this] { BeforeStep(); }, [this] { AfterStep(); });
}

SimBase::~SimBase() { sim_.RemoveHooks(hooks_); }

double SimBase::effective_track_m() const {
  return sim_.params().track_m * sim_.params().track_factor;
}

namespace {
// Heading of base_link's x axis in the horizontal plane [rad].
double TrueYaw(const Simulation& sim) {
  const Eigen::Matrix3d R = sim.T_world_base().linear();
  return std::atan2(R(1, 0), R(0, 0));
}
}  // namespace

void SimBase::ResetOdometry() {
  odometry_ = sensors::Odometry{};
  odometry_.stamp_s = sim_.time_s();
  last_ticks_ = Ticks(sim_.WheelAngles(), config_.ticks_per_rev);
  last_true_yaw_rad_ = TrueYaw(sim_);
  since_update_s_ = 0.0;
  window_.clear();
}

Result<sensors::Odometry> SimBase::Drive(double v_mps, double omega_rps, double duration_s) {
  if (!std::isfinite(v_mps) || !std::isfinite(omega_rps) || !std::isfinite(duration_s) ||
      duration_s < 0) {
    return Fail(Error::Code::kInvalidArgument,
                "Drive(v, omega, duration) needs finite values and "
                "duration >= 0");
  }
  const P3Params& p = sim_.params();
  target_ = {std::clamp(v_mps, -p.max_speed_mps, p.max_speed_mps),
             std::clamp(omega_rps, -p.max_yaw_rate_rps, p.max_yaw_rate_rps)};
  sim_.StepFor(duration_s);
  return ReadOdometry();
}

Result<sensors::Odometry> SimBase::ReadOdometry() {
  sensors::Odometry out = odometry_;
  out.stalled = sim_.WheelStalled();
  return out;
}

void SimBase::EmergencyStop() {
  target_.setZero();
  command_.setZero();
}

Result<sensors::Odometry> SimBase::Stop(double timeout_s) {
  target_.setZero();
  const double t0 = sim_.time_s();
  while (true) {
    sim_.Step(1);
    const Eigen::Vector2d speeds = sim_.BaseSpeeds();
    if (command_.isZero() && speeds[0] < kStillSpeed_mps && speeds[1] < kStillRate_rps) break;
    if (sim_.time_s() - t0 > timeout_s) {
      return Fail(Error::Code::kTimeout,
                  "base did not stop within " + std::to_string(timeout_s) + " s (still at " +
                      std::to_string(speeds[0]) + " m/s, " + std::to_string(speeds[1]) +
                      " rad/s)");
    }
  }
  return ReadOdometry();
}

// Firmware: acceleration ramp, (v, omega) -> wheel speeds, PI on wheel speed.
void SimBase::BeforeStep() {
  // Held (Simulation::HoldStill), the wheels cannot turn: the loop pauses, or its integral would
  // wind up against a wheel held off its hold angle and jolt the robot on release.
  if (sim_.held()) return;
  const P3Params& p = sim_.params();
  const double dt = sim_.timestep_s();
  command_[0] = Ramp(command_[0], target_[0], p.max_accel_mps2 * dt);
  command_[1] = Ramp(command_[1], target_[1], p.max_yaw_accel_rps2 * dt);
  const double half_track = effective_track_m() / 2;
  Eigen::Vector2d ref_rps((command_[0] - command_[1] * half_track) / p.wheel_radius_m,
                          (command_[0] + command_[1] * half_track) / p.wheel_radius_m);
  // Parked, the firmware holds the wheels where they stopped (a position loop), so the robot
  // does not roll down a slope while it scans.
  const bool parked = command_.isZero() && target_.isZero();
  if (parked && !holding_) hold_angles_ = sim_.WheelAngles();
  holding_ = parked;
  if (parked) ref_rps = kHoldGain_per_s * (hold_angles_ - sim_.WheelAngles());
  const Eigen::Vector2d error = ref_rps - sim_.WheelSpeeds();
  integral_rps_ = (integral_rps_ + kWheelKi_per_s * dt * error)
                      .cwiseMax(-kMaxIntegral_rps)
                      .cwiseMin(kMaxIntegral_rps);
  const Eigen::Vector2d ctrl = ref_rps + integral_rps_;
  sim_.SetWheelSpeeds(ctrl[0], ctrl[1]);
}

void SimBase::AfterStep() {
  since_update_s_ += sim_.timestep_s();
  if (since_update_s_ + 1e-12 >= config_.update_period_s) IntegrateOdometry();
}

// Differential-drive dead reckoning from quantized encoder increments (midpoint heading).
void SimBase::IntegrateOdometry() {
  const P3Params& p = sim_.params();
  const Eigen::Vector2d ticks = Ticks(sim_.WheelAngles(), config_.ticks_per_rev);
  const Eigen::Vector2d dticks = ticks - last_ticks_;
  last_ticks_ = ticks;
  const double tick_m = 2.0 * M_PI / config_.ticks_per_rev * p.wheel_radius_m;
  Eigen::Vector2d ds = dticks * tick_m;
  ds = ds.cwiseProduct(scale_);
  if (config_.increment_sigma > 0) {
    ds[0] *= 1.0 + config_.increment_sigma * normal_(rng_);
    ds[1] *= 1.0 + config_.increment_sigma * normal_(rng_);
  }
  const double track = effective_track_m() * (1.0 + config_.track_error);
  const double d_center = (ds[0] + ds[1]) / 2;
  double d_yaw = (ds[1] - ds[0]) / track;
  if (config_.gyro) {  // the body's true turn, plus the gyro's bias and white noise
    const double yaw = TrueYaw(sim_);
    const double dt = since_update_s_;
    d_yaw = std::remainder(yaw - last_true_yaw_rad_, 2.0 * M_PI) +
            (config_.gyro_bias_dps * dt +
             config_.gyro_noise_dps_rthz * std::sqrt(dt) * normal_(rng_)) * M_PI / 180.0;
    last_true_yaw_rad_ = yaw;
  }
  const double heading = odometry_.yaw_rad + d_yaw / 2;
  odometry_.x_m += d_center * std::cos(heading);
  odometry_.y_m += d_center * std::sin(heading);
  odometry_.yaw_rad = std::remainder(odometry_.yaw_rad + d_yaw, 2.0 * M_PI);
  window_.push_back({since_update_s_, d_center, d_yaw});
  Increment sum{0, 0, 0};
  for (const Increment& inc : window_) {
    sum.dt_s += inc.dt_s, sum.distance_m += inc.distance_m, sum.yaw_rad += inc.yaw_rad;
  }
  while (sum.dt_s - window_.front().dt_s >= config_.speed_window_s - 1e-9) {
    sum.dt_s -= window_.front().dt_s;
    sum.distance_m -= window_.front().distance_m;
    sum.yaw_rad -= window_.front().yaw_rad;
    window_.pop_front();
  }
  odometry_.v_mps = sum.distance_m / sum.dt_s;
  odometry_.omega_rps = sum.yaw_rad / sum.dt_s;
  odometry_.stamp_s = sim_.time_s();
  since_update_s_ = 0.0;
}

}  // namespace pitchlab::sim
