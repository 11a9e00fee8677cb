// The laser locked on the base while its servo holds a fixed setpoint, and the physics step that
// follows from it (Simulation::Step).

#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/sim/robot_model.hpp"
#include "pitchlab/sim/sim_base.hpp"
#include "pitchlab/sim/simulation.hpp"
#include "sim_test_worlds.hpp"

namespace pitchlab::sim {
namespace {

constexpr double kWorldStep_s = 0.002;  // kFlatWorld's, MuJoCo's default

RobotConfig Robot(P3Model model) {
  RobotConfig c;
  c.model = model;
  return c;
}

TEST(LaserLock, AtRestTheP3AtLaserLocksAndTheRobotDrivesAtItsOwnStep) {
  auto sim = Simulation::FromString(testing::kFlatWorld, "/tmp", Robot(P3Model::kP3AT));
  SimBase base(*sim);
  ASSERT_TRUE(sim->PlaceRobot(0.0, 0.0, 0.0));
  const double drive_step_s = ParamsFor(P3Model::kP3AT).locked_timestep_s;
  ASSERT_GT(drive_step_s, kWorldStep_s);
  EXPECT_EQ(sim->timestep_s(), drive_step_s);  // settled at its setpoint: locked
  const double pitch = sim->pitch_rad();
  const double t0 = sim->time_s();
  ASSERT_TRUE(base.Drive(0.5, 0.3, 2.0));
  EXPECT_NEAR(sim->time_s() - t0, 2.0, drive_step_s / 2);
  EXPECT_EQ(sim->pitch_rad(), pitch);  // accelerating, turning: the laser does not nod
  EXPECT_EQ(sim->timestep_s(), drive_step_s);

  // A new setpoint unlocks it: the servo moves the laser there at the world's step, then it locks.
  sim->SetPitchSetpoint(0.2, 0.0);
  EXPECT_EQ(sim->timestep_s(), kWorldStep_s);
  sim->StepFor(1.0);
  EXPECT_NEAR(sim->pitch_rad(), 0.2, 1e-4);
  EXPECT_EQ(sim->timestep_s(), drive_step_s);
  const double moved = sim->pitch_rad();
  ASSERT_TRUE(base.Drive(-0.3, 0.0, 1.0));
  EXPECT_EQ(sim->pitch_rad(), moved);

  // Held to scan, the pitch joint is what moves: unlocked, at the world's step.
  ASSERT_TRUE(base.Stop(3.0));
  ASSERT_TRUE(sim->HoldStill());
  EXPECT_EQ(sim->timestep_s(), kWorldStep_s);
  sim->SetPitchSetpoint(0.0, 0.0);
  sim->StepFor(1.0);
  EXPECT_NEAR(sim->pitch_rad(), 0.0, 1e-4);
  EXPECT_EQ(sim->timestep_s(), kWorldStep_s);
  sim->Release();
  sim->StepFor(0.1);
  EXPECT_EQ(sim->timestep_s(), drive_step_s);
}

// The P3-DX's turn on the spot changes with the laser locked (robot_model.cpp): its drive step
// is the world's, and its laser is never locked.
TEST(LaserLock, TheP3DxLaserStaysOnItsServo) {
  auto sim = Simulation::FromString(testing::kFlatWorld, "/tmp", Robot(P3Model::kP3DX));
  SimBase base(*sim);
  ASSERT_TRUE(sim->PlaceRobot(0.0, 0.0, 0.0));
  ASSERT_TRUE(base.Drive(0.5, 0.0, 1.0));
  EXPECT_EQ(sim->timestep_s(), kWorldStep_s);
  ASSERT_TRUE(base.Drive(-0.5, 0.0, 1.0));
  EXPECT_NE(sim->pitch_rate_rps(), 0.0);  // the servo, not a lock, holds it
}

// A world that chose its own step keeps it throughout.
TEST(LaserLock, AWorldWithItsOwnStepKeepsIt) {
  std::string xml = testing::kFlatWorld;
  const std::string option = "<option timestep=\"0.002\"/>";
  const std::size_t at = xml.find(option);
  ASSERT_NE(at, std::string::npos);
  xml.replace(at, option.size(), "<option timestep=\"0.001\"/>");
  auto sim = Simulation::FromString(xml, "/tmp", Robot(P3Model::kP3AT));
  SimBase base(*sim);
  ASSERT_TRUE(sim->PlaceRobot(0.0, 0.0, 0.0));
  ASSERT_TRUE(base.Drive(0.5, 0.0, 1.0));
  EXPECT_EQ(sim->timestep_s(), 0.001);
}

}  // namespace
}  // namespace pitchlab::sim
