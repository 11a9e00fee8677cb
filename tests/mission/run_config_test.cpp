#include "pitchlab/mission/run_config.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

TEST(RunSettings, DefaultsExploreWithTheRobotsPreset) {
  const RunSettings s = ParseRunSettings("", "test", sim::P3Model::kP3DX);
  EXPECT_EQ(s.mission.planner.robot.name, "p3dx");
  EXPECT_EQ(s.mission.planner.unknown, planning::UnknownPolicy::kPenalise);
  EXPECT_GT(s.mission.planner.unknown_penalty, 1.0);
}

// Runs keep half a metre off hazards where there is room (wheel odometry slips on rough ground);
// a planner section that leaves the clearance out keeps it, one that sets it wins.
TEST(RunSettings, PathsKeepAClearanceFromHazardsUnlessTheConfigSaysOtherwise) {
  const RunSettings d = ParseRunSettings("", "test", sim::P3Model::kP3AT);
  EXPECT_DOUBLE_EQ(d.mission.planner.clearance_m, 0.5);
  EXPECT_DOUBLE_EQ(d.mission.planner.clearance_cost, 1.0);
  const RunSettings w =
      ParseRunSettings("planner: {weights: {roughness: 5}}\n", "test", sim::P3Model::kP3AT);
  EXPECT_DOUBLE_EQ(w.mission.planner.clearance_m, 0.5);
  const RunSettings off =
      ParseRunSettings("planner: {clearance_cost: 0}\n", "test", sim::P3Model::kP3AT);
  EXPECT_DOUBLE_EQ(off.mission.planner.clearance_cost, 0.0);
  EXPECT_DOUBLE_EQ(off.mission.planner.clearance_m, 0.5);
  const RunSettings back = ParseRunSettings(RunSettingsToYaml(off), "used", sim::P3Model::kP3AT);
  EXPECT_DOUBLE_EQ(back.mission.planner.clearance_cost, 0.0);
}

TEST(RunSettings, APlannerLimitOverridesOnlyThatLimitOfThePreset) {
  const RunSettings s =
      ParseRunSettings("planner: {max_inclination_deg: 17}\n", "test", sim::P3Model::kP3AT);
  EXPECT_EQ(s.mission.planner.robot.name, "p3at");
  EXPECT_NEAR(s.mission.planner.robot.max_inclination_rad, 17 * kDeg, 1e-9);
  EXPECT_NEAR(s.mission.planner.robot.step_max_m, planning::RobotLimits::P3AT().step_max_m, 1e-12);
  EXPECT_EQ(s.mission.planner.unknown, planning::UnknownPolicy::kPenalise);
}

// The loaded P3-AT plans to 16 deg (it tips near 31 deg standing, less over rocks), also when a
// planner section leaves the limit out; the P3-DX keeps its own, lower preset.
TEST(RunSettings, TheLoadedP3AtPlansToSixteenDegrees) {
  const RunSettings at = ParseRunSettings("", "test", sim::P3Model::kP3AT);
  EXPECT_NEAR(at.mission.planner.robot.max_inclination_rad, 16 * kDeg, 1e-9);
  const RunSettings weights =
      ParseRunSettings("planner: {weights: {roughness: 5}}\n", "test", sim::P3Model::kP3AT);
  EXPECT_NEAR(weights.mission.planner.robot.max_inclination_rad, 16 * kDeg, 1e-9);
  const RunSettings dx = ParseRunSettings("", "test", sim::P3Model::kP3DX);
  EXPECT_NEAR(dx.mission.planner.robot.max_inclination_rad,
              planning::RobotLimits::P3DX().max_inclination_rad, 1e-12);
  // The inclination's fit region in cells: 3 x 3 by default, 5 x 5 for half a robot length.
  EXPECT_EQ(at.mission.layers.inclination_radius_cells, 1);
  const RunSettings footprint =
      ParseRunSettings("run: {inclination_radius_m: 0.25}\n", "test", sim::P3Model::kP3AT);
  EXPECT_EQ(footprint.mission.layers.inclination_radius_cells, 2);
  const RunSettings coarse = ParseRunSettings("run: {cell_m: 0.25, inclination_radius_m: 0.25}\n",
                                              "test", sim::P3Model::kP3AT);
  EXPECT_EQ(coarse.mission.layers.inclination_radius_cells, 1);
  EXPECT_THROW(ParseRunSettings("run: {scan_tilt_deg: 25}\n", "t", sim::P3Model::kP3AT),
               std::invalid_argument);  // above caution_tilt_deg
  EXPECT_THROW(ParseRunSettings("run: {map_range_m: 0.5}\n", "t", sim::P3Model::kP3AT),
               std::invalid_argument);  // inside the robot's own footprint
  EXPECT_NEAR(
      ParseRunSettings("run: {map_range_m: 25}\n", "t", sim::P3Model::kP3AT).mission.map_range_m,
      25.0, 1e-12);
}

TEST(RunSettings, RunKeysAreReadAndBadOnesNamed) {
  const RunSettings s =
      ParseRunSettings("run: {drive_per_stop_m: 2.5, cell_m: 0.2, algorithm: dijkstra}\n", "f.yaml",
                       sim::P3Model::kP3AT);
  EXPECT_EQ(s.mission.drive_per_stop_m, 2.5);
  EXPECT_EQ(s.cell_m, 0.2);
  EXPECT_EQ(s.mission.algorithm, planning::Algorithm::kDijkstra);
  try {
    ParseRunSettings("run: {drive_per_stop: 2}\n", "f.yaml", sim::P3Model::kP3AT);
    FAIL() << "an unknown key was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("f.yaml: run.drive_per_stop"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ParseRunSettings("run: {cell_m: 5}\n", "f.yaml", sim::P3Model::kP3AT),
               std::invalid_argument);
}

// Scan-to-map registration keeps its own acceptance (registration_eval's pairwise defaults
// reject the low-overlap stops of a run), unless the config's registration section says otherwise
// key by key.
TEST(RunSettings, TheRunRegistersWithScanToMapDefaultsAKeyGivenWins) {
  const mapping::RegistrationConfig pairwise;
  const RunSettings s = ParseRunSettings("", "t", sim::P3Model::kP3AT);
  const mapping::RegistrationConfig& r = s.mission.registration.registration;
  EXPECT_EQ(r.max_rmse_m, 0.06);
  EXPECT_EQ(r.min_inlier_ratio, 0.05);
  EXPECT_EQ(r.constraint_translation_m, 2.0)
      << "odometry slips up to 2.5 m on rugged ground; the office repeats every 2 m";
  EXPECT_GT(r.carry_max_m, s.mission.odometry_error_m + 4 * s.mission.odometry_error_per_m)
      << "a 4 m drive's bound must let odometry supply a corridor's axis";
  EXPECT_TRUE(std::isnan(pairwise.max_rmse_m)) << "pairwise: auto, from the measured noise";
  const RunSettings given = ParseRunSettings(
      "registration: {max_rmse_m: 0.02, icp_max_iterations: 30}\n", "t", sim::P3Model::kP3AT);
  const mapping::RegistrationConfig& g = given.mission.registration.registration;
  EXPECT_EQ(g.max_rmse_m, 0.02);
  EXPECT_EQ(g.icp_max_iterations, 30);
  EXPECT_EQ(g.min_inlier_ratio, 0.05);  // not given: the run's
  EXPECT_EQ(g.carry_max_m, r.carry_max_m);
}

TEST(RunSettings, TheOdometryErrorBoundIsReadAndANegativeOneNamed) {
  const RunSettings s = ParseRunSettings(
      "run: {odometry_error_m: 0.1, odometry_error_per_m: 0.05, odometry_error_deg: 1, "
      "odometry_error_dps: 0.02, odometry_error_per_rad: 0.07}\n",
      "f.yaml", sim::P3Model::kP3DX);
  EXPECT_EQ(s.mission.odometry_error_m, 0.1);
  EXPECT_EQ(s.mission.odometry_error_per_m, 0.05);
  EXPECT_EQ(s.mission.odometry_error_deg, 1.0);
  EXPECT_EQ(s.mission.odometry_error_dps, 0.02);
  EXPECT_EQ(s.mission.odometry_error_per_rad, 0.07);
  EXPECT_EQ(ParseRunSettings(RunSettingsToYaml(s), "back", sim::P3Model::kP3DX)
                .mission.odometry_error_per_rad,
            0.07);
  EXPECT_EQ(ParseRunSettings("", "f.yaml", sim::P3Model::kP3AT).mission.odometry_error_per_rad,
            0.05);
  for (const char* bad : {"run: {odometry_error_deg: -1}\n", "run: {odometry_error_per_rad: -1}\n"}) {
    try {
      ParseRunSettings(bad, "f.yaml", sim::P3Model::kP3DX);
      FAIL() << "a negative bound was accepted: " << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("f.yaml: run.odometry_error_"), std::string::npos)
          << e.what();
    }
  }
}

TEST(RunSettings, TheDriftPerMetreIsReadWrittenBackAndANegativeOneNamed) {
  EXPECT_EQ(ParseRunSettings("", "f.yaml", sim::P3Model::kP3AT).mission.drift_per_m, 0.2);
  const RunSettings off = ParseRunSettings("run: {drift_per_m: 0}\n", "f.yaml", sim::P3Model::kP3AT);
  EXPECT_EQ(off.mission.drift_per_m, 0.0);
  EXPECT_EQ(ParseRunSettings(RunSettingsToYaml(off), "back", sim::P3Model::kP3AT).mission.drift_per_m,
            0.0);
  for (const char* bad : {"run: {drift_per_m: -0.1}\n", "run: {drift_per_m: .inf}\n"}) {
    try {
      ParseRunSettings(bad, "f.yaml", sim::P3Model::kP3AT);
      FAIL() << "accepted: " << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("f.yaml: run.drift_per_m"), std::string::npos)
          << e.what();
    }
  }
}

TEST(RunSettings, TheTiltToleranceIsReadAndAnImpossibleOneNamed) {
  EXPECT_EQ(ParseRunSettings("", "f.yaml", sim::P3Model::kP3DX).mission.tilt_tolerance_deg, 0.5);
  EXPECT_EQ(ParseRunSettings("run: {tilt_tolerance_deg: 1.5}\n", "f.yaml", sim::P3Model::kP3DX)
                .mission.tilt_tolerance_deg,
            1.5);
  for (const char* bad : {"run: {tilt_tolerance_deg: 0}\n", "run: {tilt_tolerance_deg: 120}\n",
                          "run: {tilt_tolerance_deg: .nan}\n"}) {
    try {
      ParseRunSettings(bad, "f.yaml", sim::P3Model::kP3DX);
      FAIL() << "accepted: " << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("f.yaml: run.tilt_tolerance_deg"), std::string::npos)
          << e.what();
    }
  }
}

TEST(RunSettings, LoopClosureIsOffUnlessTheRunSectionSwitchesItOn) {
  EXPECT_FALSE(ParseRunSettings("", "f.yaml", sim::P3Model::kP3DX)
                   .mission.registration.loop_closure.enabled);
  const RunSettings on =
      ParseRunSettings("run: {loop_closure: true}\n", "f.yaml", sim::P3Model::kP3DX);
  EXPECT_TRUE(on.mission.registration.loop_closure.enabled);
  EXPECT_TRUE(ParseRunSettings(RunSettingsToYaml(on), "back", sim::P3Model::kP3DX)
                  .mission.registration.loop_closure.enabled);
  try {
    ParseRunSettings("run: {loop_closure: sometimes}\n", "f.yaml", sim::P3Model::kP3DX);
    FAIL() << "accepted a loop_closure that is no boolean";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("f.yaml: run.loop_closure has the wrong type"),
              std::string::npos)
        << e.what();
  }
}

TEST(RunSettings, LinesAreSetRightOnlyWhenTheRunSectionAsks) {
  EXPECT_FALSE(ParseRunSettings("", "f.yaml", sim::P3Model::kP3DX).mission.set_lines_right);
  const RunSettings on =
      ParseRunSettings("run: {set_lines_right: true}\n", "f.yaml", sim::P3Model::kP3DX);
  EXPECT_TRUE(on.mission.set_lines_right);
  EXPECT_TRUE(
      ParseRunSettings(RunSettingsToYaml(on), "back", sim::P3Model::kP3DX).mission.set_lines_right);
  EXPECT_THROW(ParseRunSettings("run: {set_lines_right: 2deg}\n", "f.yaml", sim::P3Model::kP3DX),
               std::invalid_argument);
}

TEST(RunSettings, TheMountIsCalibratedUnlessTheRunSectionSaysNo) {
  EXPECT_TRUE(ParseRunSettings("", "f.yaml", sim::P3Model::kP3AT).mission.calibrate_mount);
  const RunSettings off =
      ParseRunSettings("run: {calibrate_mount: false}\n", "f.yaml", sim::P3Model::kP3AT);
  EXPECT_FALSE(off.mission.calibrate_mount);
  EXPECT_FALSE(ParseRunSettings(RunSettingsToYaml(off), "back", sim::P3Model::kP3AT)
                   .mission.calibrate_mount);
  EXPECT_THROW(ParseRunSettings("run: {calibrate_mount: often}\n", "f.yaml", sim::P3Model::kP3AT),
               std::invalid_argument);
}

TEST(RunSettings, APathBehindIsDrivenInReverseUnlessTheRunSectionSaysNo) {
  EXPECT_TRUE(ParseRunSettings("", "f.yaml", sim::P3Model::kP3AT).mission.follower.reverse);
  const RunSettings off =
      ParseRunSettings("run: {reverse: false}\n", "f.yaml", sim::P3Model::kP3AT);
  EXPECT_FALSE(off.mission.follower.reverse);
  EXPECT_FALSE(ParseRunSettings(RunSettingsToYaml(off), "back", sim::P3Model::kP3AT)
                   .mission.follower.reverse);
  EXPECT_THROW(ParseRunSettings("run: {reverse: 1m}\n", "f.yaml", sim::P3Model::kP3AT),
               std::invalid_argument);
}

TEST(RunSettings, WrittenYamlReadsBackTheSame) {
  const RunSettings s = ParseRunSettings(
      "run: {goal_tolerance_m: 0.3, odometry_error_m: 0.2, tilt_tolerance_deg: 0.8}\n"
      "planner: {weights: {roughness: 5}}\n"
      "registration: {max_rmse_m: 0.03}\n",
      "t", sim::P3Model::kP3AT);
  const RunSettings back = ParseRunSettings(RunSettingsToYaml(s), "back", sim::P3Model::kP3AT);
  EXPECT_EQ(RunSettingsToYaml(back), RunSettingsToYaml(s));
}

}  // namespace
}  // namespace pitchlab::mission
