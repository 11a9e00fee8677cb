// Register() held to real data: two consecutive scans of a corridor from a nodding SICK LMS
// (3DTK's example data, tests/data/real/3dtk_corridor, with slam6d's registered poses as the
// reference, good to about 0.5-1 deg), and a simulated pair scaled by 0.01 and by 10.

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "sim_scans.hpp"

namespace pitchlab::mapping {
namespace {

const std::string kDir = PITCHLAB_3DTK_CORRIDOR_DIR;

// slam6d's pose is a reference, not the truth (SOURCES.md): within 1 deg / 5 cm is the same pose.
constexpr double kSameRotation_deg = 1.0;
constexpr double kSameTranslation_m = 0.05;

struct RealScan {
  PointCloud cloud;
  Eigen::Isometry3d odometry, reference;
};

RealScan Load(const std::string& name) {
  Result<sensors::Scan3D> scan = sensors::ReadCloudFile(kDir + "/" + name + ".3d");
  EXPECT_TRUE(scan) << scan.error().message;
  Result<Eigen::Isometry3d> ref = sensors::Read3dtkFrames(kDir + "/" + name + ".frames.slam6d_2009");
  EXPECT_TRUE(ref) << ref.error().message;
  // As `register` reads it: each nodding line set right by the floor it crossed (line_pitch.hpp).
  PointCloud cloud = CloudFromScan(*scan);
  EXPECT_GT(RectifyLinePitch(cloud, Eigen::Vector3f::Zero()).corrected, 50u);
  return {cloud, scan->T_world_base, *ref};
}

class RealCorridor : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    first_ = new RealScan(Load("scan000"));
    second_ = new RealScan(Load("scan001"));
  }
  static void TearDownTestSuite() {
    delete first_;
    delete second_;
  }
  // T_target_source of slam6d's poses and of odometry, `forward`: scan001 into scan000.
  static Eigen::Isometry3d Reference(bool forward) {
    const Eigen::Isometry3d T = first_->reference.inverse() * second_->reference;
    return forward ? T : T.inverse();
  }
  static Eigen::Isometry3d Odometry(bool forward) {
    const Eigen::Isometry3d T = first_->odometry.inverse() * second_->odometry;
    return forward ? T : T.inverse();
  }
  static Result<RegistrationResult> Align(bool forward, const RegistrationPrior& prior) {
    return forward ? Register(first_->cloud, second_->cloud, prior, {})
                   : Register(second_->cloud, first_->cloud, prior, {});
  }
  static inline RealScan* first_ = nullptr;
  static inline RealScan* second_ = nullptr;
};

// Default settings, both ways round, with the odometry prior (wheel odometry over 1.6 m: bounded
// to 10 cm / 1 deg; it is 1.7 cm / 0.7 deg off the reference) and without any: each a success at
// the reference's pose. (Before the gates followed the data, the inlier RMS of 3.3 cm failed the
// fixed 3 cm gate every time.)
TEST_F(RealCorridor, TheSharedPairRegistersToTheReferenceBothWaysWithAndWithoutAPrior) {
  for (const bool forward : {true, false}) {
    for (const bool with_prior : {true, false}) {
      RegistrationPrior prior;
      if (with_prior) {
        prior.odometry = Odometry(forward);
        prior.odometry_uncertainty = GuessUncertainty{0.1, 1.0};
      }
      Result<RegistrationResult> r = Align(forward, prior);
      ASSERT_TRUE(r) << r.error().message;
      SCOPED_TRACE(std::string(forward ? "scan001 -> scan000" : "scan000 -> scan001") +
                   (with_prior ? ", odometry prior" : ", no prior"));
      EXPECT_TRUE(r->success) << r->reason;
      EXPECT_DOUBLE_EQ(r->settings.length_scale, 1.0);
      const PoseError e = ComparePoses(r->T_target_source, Reference(forward));
      EXPECT_LT(e.rotation_deg, kSameRotation_deg) << r->reason;
      // With the lines as recorded the reverse pair came out 5.2 cm off (the washboard floor
      // pulled it); set right, 0.9 cm.
      EXPECT_LT(e.translation_m, kSameTranslation_m) << r->reason;
    }
  }
}

// scan001 -> scan000 (the pair whose points mostly overlap): the result fits the scans at full
// resolution as well as slam6d's pose does (the share of points within 5 cm no more than 1 point
// below the reference's, issue 16), and lies within 1 deg / 5 cm of it. ICP's last iterations at
// the inlier band did that (mapping/README.md): ending at 0.15 m it fitted 69 % against 74.7 %.
TEST_F(RealCorridor, TheOverlappingPairFitsAsWellAsTheReferencePose) {
  const double reference_fit = ShareWithin(first_->cloud, second_->cloud, Reference(true), 0.05);
  for (const bool with_prior : {true, false}) {
    RegistrationPrior prior;
    if (with_prior) {
      prior.odometry = Odometry(true);
      prior.odometry_uncertainty = GuessUncertainty{0.1, 1.0};
    }
    Result<RegistrationResult> r = Align(true, prior);
    ASSERT_TRUE(r) << r.error().message;
    SCOPED_TRACE(with_prior ? "odometry prior" : "no prior");
    ASSERT_TRUE(r->success) << r->reason;
    const double fit = ShareWithin(first_->cloud, second_->cloud, r->T_target_source, 0.05);
    EXPECT_GE(fit, reference_fit - 0.01) << "reference " << reference_fit;
    const PoseError e = ComparePoses(r->T_target_source, Reference(true));
    EXPECT_LT(e.rotation_deg, kSameRotation_deg);
    EXPECT_LT(e.translation_m, kSameTranslation_m);
  }
}

// Priors 1-3 m along the corridor or 10-30 deg off, with a stated error bound that does not hold
// the truth, and with none: whatever comes out is the reference's pose or is not a success.
TEST_F(RealCorridor, AWrongPriorNeverGivesAFalseSuccess) {
  struct Case {
    double along_m, turn_deg;
  };
  const Case cases[] = {{1, 0}, {2, 0}, {-1, 0}, {-2, 0}, {-3, 0}, {0, 10}, {0, -20}, {0, 30}};
  for (const Case& c : cases) {
    for (const bool bounded : {true, false}) {
      RegistrationPrior prior;
      prior.odometry =
          Odometry(true) * PoseFromXyzRpyDeg(c.along_m, 0, 0, 0, 0, c.turn_deg);
      if (bounded) {  // a bound that excludes the truth: the prior is off by more
        prior.odometry_uncertainty =
            GuessUncertainty{0.5 * std::abs(c.along_m), 0.5 * std::abs(c.turn_deg)};
      }
      Result<RegistrationResult> r = Align(true, prior);
      ASSERT_TRUE(r) << r.error().message;
      const PoseError e = ComparePoses(r->T_target_source, Reference(true));
      const bool at_reference =
          e.rotation_deg < kSameRotation_deg && e.translation_m < kSameTranslation_m;
      EXPECT_TRUE(!r->success || at_reference)
          << "prior " << c.along_m << " m along, " << c.turn_deg << " deg, "
          << (bounded ? "bounded" : "no bound") << ": success " << e.rotation_deg << " deg / "
          << e.translation_m << " m off the reference: " << r->reason;
    }
  }
}

// The case that was a false success: 2 m back along the corridor, bounded to 1 m. The bound held
// a pose 1.6 m off the reference (38.8 % inliers); the scans fit the reference's far better
// (53.8 %: 1.39x, past the contradiction margin of 1.2, registration.cpp), and that pose puts 19 %
// of the source's points the target could judge where the target's beams passed (3 % at the
// reference): free space refutes it before the contradiction is asked.
TEST_F(RealCorridor, APriorBoundTheScansContradictIsNoSuccess) {
  RegistrationPrior prior;
  prior.odometry = Odometry(true) * PoseFromXyzRpyDeg(-2, 0, 0, 0, 0, 0);
  prior.odometry_uncertainty = GuessUncertainty{1.0, 15.0};
  Result<RegistrationResult> r = Align(true, prior);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->success) << r->reason;
  EXPECT_EQ(r->outcome, RegistrationOutcome::kFailure) << r->reason;
  EXPECT_NE(r->reason.find("free space"), std::string::npos) << r->reason;
  EXPECT_GT(r->free_space.source_violating, 0.1) << r->reason;
}

// A simulated pair scaled by 0.01 and by 10 (points, prior and bound alike) registers to the same
// rotation with default settings: the lengths follow the data (length_scale resolves to exactly
// 0.01 and 10) and the result scales with it.
TEST(Register, AScaledSceneRegistersToTheSameRotationWithDefaultSettings) {
  const sensors::Scan3D a = testing::SimulatedScan("office", -8, 0, 0, 1);
  const sensors::Scan3D b = testing::SimulatedScan("office", -7.2, 0.3, 12, 2);
  const Eigen::Isometry3d truth = a.T_world_base.inverse() * b.T_world_base;
  const Eigen::Vector3f laser = sensors::MountConfig{}.BaseToLaser(0.0).translation().cast<float>();
  auto scaled = [](const sensors::Scan3D& s, float k) {
    PointCloud out = CloudFromScan(s);
    for (Eigen::Vector3f& p : out) p *= k;
    return out;
  };
  std::optional<Eigen::Isometry3d> unscaled;
  for (const float k : {1.0f, 0.01f, 10.0f}) {
    RegistrationPrior prior;
    prior.source_sensor = prior.target_sensor = laser * k;
    Eigen::Isometry3d guess = truth * PoseFromXyzRpyDeg(0.3, -0.2, 0, 0, 0, 4);
    guess.translation() *= k;
    prior.odometry = guess;
    prior.odometry_uncertainty = GuessUncertainty{0.5 * k, 8.0};
    Result<RegistrationResult> r = Register(scaled(a, k), scaled(b, k), prior, {});
    ASSERT_TRUE(r) << r.error().message;
    SCOPED_TRACE("scale " + std::to_string(k));
    EXPECT_TRUE(r->success) << r->reason;
    EXPECT_NEAR(r->settings.length_scale, k, 1e-6 * k);
    Eigen::Isometry3d unit = r->T_target_source;
    unit.translation() /= k;
    const PoseError e = ComparePoses(unit, truth);
    EXPECT_LT(e.rotation_deg, 0.5) << r->reason;
    EXPECT_LT(e.translation_m, 0.03) << r->reason;
    if (!unscaled) {
      unscaled = unit;
    } else {
      const PoseError d = ComparePoses(unit, *unscaled);
      EXPECT_LT(d.rotation_deg, 0.05) << "the same rotation as unscaled";
    }
  }
}

}  // namespace
}  // namespace pitchlab::mapping
