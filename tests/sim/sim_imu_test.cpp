// SimImu: the gyro triad integrates the body's true turn, plus bounded, seeded errors.

#include "pitchlab/sim/sim_imu.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "pitchlab/sim/sim_base.hpp"
#include "sim_test_worlds.hpp"

namespace pitchlab::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Rig {
  std::unique_ptr<Simulation> sim;
  std::unique_ptr<SimBase> base;
};

Rig Make() {
  RobotConfig robot;
  robot.model = P3Model::kP3AT;
  Rig r;
  r.sim = Simulation::FromString(testing::kFlatWorld, "/tmp", robot);
  Result<Eigen::Isometry3d> pose = r.sim->PlaceRobot(-2.0, 0.0, 0.0);
  if (!pose) throw std::runtime_error(pose.error().message);
  r.base = std::make_unique<SimBase>(*r.sim, OdometryConfig{});
  return r;
}

// Angle between the IMU's and the truth's rotation from `a` to `b` [rad].
double TurnError(const Eigen::Quaterniond& imu_a, const Eigen::Quaterniond& imu_b,
                 const Eigen::Quaterniond& true_a, const Eigen::Quaterniond& true_b) {
  const Eigen::Quaterniond sensed = imu_a.conjugate() * imu_b;
  const Eigen::Quaterniond truth = true_a.conjugate() * true_b;
  return Eigen::AngleAxisd(sensed.conjugate() * truth).angle();
}

TEST(SimImu, WithoutErrorsItTurnsExactlyAsTheBody) {
  Rig r = Make();
  ImuConfig perfect;
  perfect.gyro_bias_dps = perfect.gyro_noise_dps_rthz = 0.0;
  SimImu imu(*r.sim, perfect);
  const Eigen::Quaterniond imu_a = imu.Orientation();
  const Eigen::Quaterniond true_a(r.sim->T_world_base().rotation());
  ASSERT_TRUE(r.base->Drive(0.2, 0.5, 2.0));  // an arc of ~60 deg
  const Eigen::Quaterniond imu_b = imu.Orientation();
  const Eigen::Quaterniond true_b(r.sim->T_world_base().rotation());
  EXPECT_GT(Eigen::AngleAxisd(true_a.conjugate() * true_b).angle(), 30 * kDeg);
  EXPECT_LT(TurnError(imu_a, imu_b, true_a, true_b), 1e-9);
}

TEST(SimImu, ItsErrorsOverAScanStayWithinTheGyrosSpecification) {
  // A seed scan lasts ~18 s: 0.003 deg/s of bias and 0.008 deg/s/sqrt(Hz) of noise give 0.16 +
  // 0.10 deg at 3 sigma, read every line (90 ms) as the scan source does.
  Rig r = Make();
  ImuConfig config;
  config.seed = 7;
  SimImu imu(*r.sim, config);
  SimImu twin(*r.sim, config);
  const Eigen::Quaterniond imu_a = imu.Orientation();
  (void)twin.Orientation();
  const Eigen::Quaterniond true_a(r.sim->T_world_base().rotation());
  double worst = 0;
  for (int line = 0; line < 200; ++line) {
    ASSERT_TRUE(r.base->Drive(0.0, line < 100 ? 0.3 : -0.3, 0.09));
    const Eigen::Quaterniond imu_b = imu.Orientation();
    const Eigen::Quaterniond twin_b = twin.Orientation();
    EXPECT_TRUE(imu_b.isApprox(twin_b, 1e-15)) << "the same seed, the same readings";
    const Eigen::Quaterniond true_b(r.sim->T_world_base().rotation());
    worst = std::max(worst, TurnError(imu_a, imu_b, true_a, true_b));
  }
  EXPECT_GT(worst, 1e-4 * kDeg);  // errors are on
  EXPECT_LT(worst, 0.26 * kDeg);
}

TEST(ImuConfig, RejectsBadValuesNamingTheField) {
  ImuConfig c;
  c.gyro_noise_dps_rthz = -1;
  try {
    c.Validate();
    FAIL() << "accepted a negative noise density";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("imu.gyro_noise_dps_rthz"), std::string::npos);
  }
}

}  // namespace
}  // namespace pitchlab::sim
