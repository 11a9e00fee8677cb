#include "pitchlab/sim/sim_imu.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pitchlab::sim {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
constexpr std::uint64_t kSeedSalt = 0x696d75;  // "imu": its own stream beside the odometry's
}  // namespace

void ImuConfig::Validate() const {
  auto invalid = [](const char* field, double value, const char* allowed) {
    std::ostringstream os;
    os << "imu." << field << " = " << value << " is invalid (" << allowed << ")";
    throw std::invalid_argument(os.str());
  };
  if (!(gyro_bias_dps >= 0 && gyro_bias_dps <= 10))
    invalid("gyro_bias_dps", gyro_bias_dps, "0 .. 10");
  if (!(deskew_min_deg >= 0 && deskew_min_deg <= 90)) {
    invalid("deskew_min_deg", deskew_min_deg, "0 .. 90");
  }
  if (!(gyro_noise_dps_rthz >= 0 && gyro_noise_dps_rthz <= 10)) {
    invalid("gyro_noise_dps_rthz", gyro_noise_dps_rthz, "0 .. 10");
  }
}

SimImu::SimImu(const Simulation& sim, const ImuConfig& config)
    : sim_(sim), config_(config), rng_(config.seed ^ kSeedSalt) {
  config_.Validate();
  for (int a = 0; a < 3; ++a) bias_rps_[a] = config_.gyro_bias_dps * kDegToRad * normal_(rng_);
  true_last_ = Eigen::Quaterniond(sim_.T_world_base().rotation());
  sensed_ = true_last_;
  last_s_ = sim_.time_s();
}

Eigen::Quaterniond SimImu::Orientation() {
  const Eigen::Quaterniond true_now(sim_.T_world_base().rotation());
  const double dt = sim_.time_s() - last_s_;
  // Integrated over dt, white rate noise of density sigma is a rotation of sigma * sqrt(dt) per
  // axis (body frame); the bias adds bias * dt. Exact in distribution for any read pattern.
  Eigen::Vector3d error = bias_rps_ * dt;
  const double walk = config_.gyro_noise_dps_rthz * kDegToRad * std::sqrt(std::max(dt, 0.0));
  for (int a = 0; a < 3; ++a) error[a] += walk * normal_(rng_);
  const Eigen::Quaterniond body_turn = true_last_.conjugate() * true_now;
  Eigen::Quaterniond err = Eigen::Quaterniond::Identity();
  if (error.norm() > 0) err = Eigen::AngleAxisd(error.norm(), error.normalized());
  sensed_ = (sensed_ * body_turn * err).normalized();
  true_last_ = true_now;
  last_s_ = sim_.time_s();
  return sensed_;
}

}  // namespace pitchlab::sim
