#include "pitchlab/sim/simulation.hpp"

#include "pitchlab/sim/sim_base.hpp"

#include <dirent.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "pitchlab/sim/robot_model.hpp"
#include "pitchlab/sim/world.hpp"
#include "scoped_temp_dir.hpp"
#include "sim_test_worlds.hpp"

namespace pitchlab::sim {
namespace {

using testing::kFlatWorld;
using testing::kWallWorld;
using testing::kBoxFloorWorld;
using test_support::ScopedTempDir;

constexpr double kGroundTolerance_m = 0.005;  // tyre/contact softness sag
constexpr double kMountTolerance_m = 0.005;

RobotConfig Robot(P3Model model) {
  RobotConfig c;
  c.model = model;
  return c;
}

class RobotModels : public ::testing::TestWithParam<P3Model> {};
INSTANTIATE_TEST_SUITE_P(Sim, RobotModels, ::testing::Values(P3Model::kP3AT, P3Model::kP3DX),
                         [](const auto& info) {
                           return std::string(info.param == P3Model::kP3AT ? "P3AT" : "P3DX");
                         });

TEST_P(RobotModels, RobotDocumentLoadsInMujocoWithAllNamedElements) {
  const std::string xml = RobotMjcfDocument(Robot(GetParam()));
  const ScopedTempDir dir("robot_test");
  const std::string path = (dir / "robot.xml").string();
  ASSERT_TRUE(std::ofstream(path) << xml << std::flush);
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  EXPECT_GE(mj_name2id(m, mjOBJ_BODY, kRobotBody), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_SITE, kBaseLinkSite), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_SITE, kLaserSite), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_JOINT, kPitchJoint), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_ACTUATOR, kPitchActuator), 0);
  const P3Params& p = ParamsFor(GetParam());
  const int body = mj_name2id(m, mjOBJ_BODY, kRobotBody);
  EXPECT_NEAR(m->body_subtreemass[body], p.base_mass_kg + p.laser_mass_kg + p.battery_mass_kg, 1e-6);
  mj_deleteModel(m);
}

// The LMS200 (4.5 kg, half a metre up, ahead of the centre) makes the robot top-heavy; the three
// batteries low in the chassis keep the P3-AT upright well past the 35 % grade (19.3 deg) it is
// rated to climb: standing, it would tip forward over the front tyres' contact only past ~30 deg.
TEST(Simulation, LoadedP3AtTipsForwardOnlyWellPastItsRatedGrade) {
  const std::string xml = RobotMjcfDocument(Robot(P3Model::kP3AT));
  char error[1000] = "";
  const ScopedTempDir dir("robot_tip");
  const std::string path = (dir / "robot.xml").string();
  ASSERT_TRUE(std::ofstream(path) << xml << std::flush);
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  const int body = mj_name2id(m, mjOBJ_BODY, kRobotBody);
  const int site = mj_name2id(m, mjOBJ_SITE, kBaseLinkSite);
  const double com_x = d->subtree_com[3 * body] - d->site_xpos[3 * site];
  const double com_z = d->subtree_com[3 * body + 2] - d->site_xpos[3 * site + 2];
  const double front_contact_x = ParamsFor(P3Model::kP3AT).wheelbase_m / 2;
  const double tip_deg = std::atan2(front_contact_x - com_x, com_z) * 180.0 / M_PI;
  constexpr double kRatedGrade_deg = 19.3, kMargin_deg = 6.0;  // braking, bumps, a turning pivot
  EXPECT_GT(tip_deg, kRatedGrade_deg + kMargin_deg) << "CoM x " << com_x << " z " << com_z;
  EXPECT_LT(com_z, 0.25);  // chassis, batteries, wheels and laser: not the laser's height
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST_P(RobotModels, SettlesOnFlatFloorWithBaseLinkAtGroundAndLaserAtMountHeight) {
  const RobotConfig robot = Robot(GetParam());
  auto sim = Simulation::FromString(kFlatWorld, "/tmp", robot);
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(0.5, -1.0, 0.3);
  ASSERT_TRUE(pose) << pose.error().message;
  EXPECT_NEAR(pose->translation().z(), 0.0, kGroundTolerance_m);
  EXPECT_NEAR(pose->translation().x(), 0.5, 0.01);
  EXPECT_NEAR(pose->translation().y(), -1.0, 0.01);
  const Eigen::Isometry3d T_world_laser = sim->T_world_laser();
  const double mount_z = (robot.mount.t_base_mount_m + robot.mount.t_mount_laser_m).z();
  EXPECT_NEAR(T_world_laser.translation().z(), mount_z, kMountTolerance_m);
  // The generated site agrees with the mount model (Eq. 1's frames).
  const Eigen::Isometry3d T_base_laser = pose->inverse() * T_world_laser;
  const Eigen::Isometry3d expected = robot.mount.BaseToLaser(sim->pitch_rad());
  EXPECT_TRUE(T_base_laser.isApprox(expected, 1e-3)) << T_base_laser.matrix();
  EXPECT_TRUE(sim->TakeWarnings().empty());
}

TEST(Simulation, ReadsThePitchlabCustomFields) {
  auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(P3Model::kP3DX));
  const WorldInfo& w = sim->world();
  EXPECT_EQ(w.description, "flat test floor");
  ASSERT_TRUE(w.bounds);
  EXPECT_EQ(*w.bounds, Eigen::Vector4d(-9, -9, 9, 9));
  ASSERT_TRUE(w.default_start);
  EXPECT_NEAR((*w.default_start)[2], M_PI / 2, 1e-12);
  ASSERT_TRUE(w.geodetic_origin);
  EXPECT_NEAR(sim->timestep_s(), 0.002, 1e-12);
}

// The world with the robot added is compiled from memory: a temp folder that cannot be written
// (full, read-only, or not there) stops no run, and a run killed while its world loads leaves no
// file behind (until session 36 the composed text went through TMPDIR/pitchlab_world_*.xml).
TEST(Simulation, LoadsAWorldWithoutATempFolder) {
  const char* old = std::getenv("TMPDIR");
  const std::string saved = old ? old : "";
  ::setenv("TMPDIR", "/nonexistent/pitchlab_no_temp_folder", 1);
  std::unique_ptr<Simulation> sim;
  EXPECT_NO_THROW(sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(P3Model::kP3DX)));
  old ? ::setenv("TMPDIR", saved.c_str(), 1) : ::unsetenv("TMPDIR");
  ASSERT_TRUE(sim);
  EXPECT_EQ(sim->world().description, "flat test floor");
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(1.0, 2.0, 0.0);
  EXPECT_TRUE(pose) << pose.error().message;
}

// An <include>d part of a world, named relative to the world's folder, is part of it (through a
// temp file MuJoCo 2.2.2 refused it: "No directory").
TEST(Simulation, AnIncludedFileIsPartOfTheWorld) {
  const ScopedTempDir dir("simulation");
  ASSERT_TRUE(std::ofstream(dir / "part.xml") << R"(<mujoco><worldbody>
    <geom name="included_box" type="box" pos="5 0 0.5" size="0.5 0.5 0.5"/>
  </worldbody></mujoco>)" << std::flush);
  const auto sim = Simulation::FromString(R"(<mujoco><include file="part.xml"/><worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/></worldbody></mujoco>)",
                                          dir.path().string(), Robot(P3Model::kP3DX));
  EXPECT_GE(mj_name2id(sim->model(), mjOBJ_GEOM, "included_box"), 0);
}

TEST(Simulation, PlacementInsideAnObstacleIsAClearError) {
  auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(P3Model::kP3AT));
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(5.0, 0.0, 0.0);
  ASSERT_FALSE(pose);
  EXPECT_EQ(pose.error().code, Error::Code::kInvalidArgument);
  EXPECT_NE(pose.error().message.find("obstacle"), std::string::npos) << pose.error().message;
}

TEST(Simulation, PlacementOverlappingAnObstacleEdgeIsAClearError) {
  auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(P3Model::kP3AT));
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(4.35, 0.0, 0.0);  // nose 0.1 m into the box
  ASSERT_FALSE(pose);
  EXPECT_NE(pose.error().message.find("obstacle"), std::string::npos) << pose.error().message;
}

TEST(Simulation, PlacementOnTopOfAThinWallIsAClearError) {
  auto sim = Simulation::FromString(kBoxFloorWorld, "/tmp", Robot(P3Model::kP3AT));
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(3.0, 1.0, 0.0);
  ASSERT_FALSE(pose);
  EXPECT_EQ(pose.error().code, Error::Code::kInvalidArgument);
  EXPECT_NE(pose.error().message.find("not on drivable ground"), std::string::npos)
      << pose.error().message;
}

// A world of boxes only (no terrain geom): the first surface from above is not always ground.
constexpr char kTableWorld[] = R"(
<mujoco model="table">
  <worldbody>
    <geom name="floor" type="box" pos="0 0 -0.05" size="10 10 0.05"/>
    <geom name="table_top" type="box" pos="3 0 0.75" size="1 1 0.02"/>
    <geom name="block" type="box" pos="-3 0 4" size="2 2 4"/>
  </worldbody>
</mujoco>)";

TEST(Simulation, PlacementOnATableTopOrARoofIsAClearError) {
  auto sim = Simulation::FromString(kTableWorld, "/tmp", Robot(P3Model::kP3AT));
  for (const double x : {3.0, -3.0}) {  // the table (0.73 m above the floor), the block (8 m)
    Result<Eigen::Isometry3d> pose = sim->PlaceRobot(x, 0.0, 0.0);
    ASSERT_FALSE(pose) << x;
    EXPECT_EQ(pose.error().code, Error::Code::kInvalidArgument);
    EXPECT_NE(pose.error().message.find("is on top of an obstacle, not on the ground"),
              std::string::npos)
        << pose.error().message;
  }
  EXPECT_TRUE(sim->PlaceRobot(0.0, 5.0, 0.0));  // the floor itself
}

TEST(Simulation, PlacementOnAnEvenSlopeSettlesTiltedLikeTheSlope) {
  auto sim = Simulation::FromString(kBoxFloorWorld, "/tmp", Robot(P3Model::kP3AT));
  SimBase base(*sim);  // its wheel servo holds the robot on the slope, as the P3 firmware does
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(-5.0, 0.0, 0.0);
  ASSERT_TRUE(pose) << pose.error().message;
  const double tilt_deg = std::acos(pose->linear()(2, 2)) * 180.0 / M_PI;
  constexpr double kTiltTolerance_deg = 1.0;
  EXPECT_NEAR(tilt_deg, 10.0, kTiltTolerance_deg);
  // Parked for as long as a 3D scan takes, it stays put (soft contacts alone creep mm/s).
  const Eigen::Vector3d before = sim->T_world_base().translation();
  sim->StepFor(16.0);
  constexpr double kCreep_m = 0.005;
  EXPECT_LT((sim->T_world_base().translation() - before).norm(), kCreep_m);
}

// A plane rising 20 deg towards +x as a MuJoCo heightfield (the terrain's contact type), written
// to `dir`: MuJoCo's binary hfield is int32 rows, int32 columns, then float32 heights.
void WriteSlopeHeightfield(const std::filesystem::path& dir) {
  constexpr std::int32_t kN = 81;
  std::ofstream out(dir / "slope.bin", std::ios::binary);
  out.write(reinterpret_cast<const char*>(&kN), sizeof kN);
  out.write(reinterpret_cast<const char*>(&kN), sizeof kN);
  for (int row = 0; row < kN; ++row) {
    for (int col = 0; col < kN; ++col) {
      const float h = static_cast<float>(col) / (kN - 1);  // scaled by the size's 2.91 m below
      out.write(reinterpret_cast<const char*>(&h), sizeof h);
    }
  }
}

// 8 m across, 8 m x tan(20 deg) = 2.912 m high.
constexpr char kSlopeHeightfieldWorld[] = R"(
<mujoco model="hslope">
  <asset><hfield name="slope" file="slope.bin" size="4 4 2.911762 1"/></asset>
  <worldbody>
    <geom name="ground" type="hfield" hfield="slope" condim="3" friction="1 0.005 0.0001"/>
  </worldbody>
</mujoco>)";

// Tyres on a 20 deg slope (friction 1 > tan 20 deg) do not slide. MuJoCo's soft contacts alone
// let the stopped robot creep 1.1-1.6 mm over a scan's 16 s on this heightfield; the noslip pass
// (simulation.cpp) holds it to 0.2-0.3 mm, a tenth of the LMS200's 5 mm range noise and under
// its 10 mm resolution.
TEST(Simulation, StoppedOnATwentyDegreeHeightfieldSlopeTheRobotStaysPut) {
  const ScopedTempDir dir("hslope");
  WriteSlopeHeightfield(dir.path());
  for (const double yaw : {0.0, M_PI, M_PI / 2}) {  // facing uphill, downhill, across
    auto sim =
        Simulation::FromString(kSlopeHeightfieldWorld, dir.path().string(), Robot(P3Model::kP3AT));
    SimBase base(*sim);
    ASSERT_TRUE(sim->PlaceRobot(0.0, 0.0, yaw));
    ASSERT_TRUE(base.Drive(0.15, 0.0, 1.0));
    ASSERT_TRUE(base.Drive(0.0, 0.0, 0.5));
    ASSERT_TRUE(base.Stop(3.0)) << "yaw " << yaw;
    const Eigen::Vector3d before = sim->T_world_base().translation();
    sim->StepFor(16.0);
    constexpr double kCreep_m = 0.0005;
    EXPECT_LT((sim->T_world_base().translation() - before).norm(), kCreep_m) << "yaw " << yaw;
  }
}

// Held for a scan on the same slope (Simulation::HoldStill), the robot does not move at all, the
// pitch joint follows a 60 deg nod as it does under full physics (to 0.01 deg: the base, as good
// as immovable in both), and on release the contacts are back and the robot settles where the
// one that was never held is.
TEST(Simulation, HeldOnTheSlopeOnlyThePitchJointMovesAndReleaseRestoresTheContacts) {
  const ScopedTempDir dir("hslope");
  WriteSlopeHeightfield(dir.path());
  std::vector<std::unique_ptr<Simulation>> sims;
  std::vector<std::unique_ptr<SimBase>> bases;
  for (int i = 0; i < 2; ++i) {
    sims.push_back(
        Simulation::FromString(kSlopeHeightfieldWorld, dir.path().string(), Robot(P3Model::kP3AT)));
    bases.push_back(std::make_unique<SimBase>(*sims.back()));
    ASSERT_TRUE(sims.back()->PlaceRobot(0.0, 0.0, 0.0));
    ASSERT_TRUE(bases.back()->Stop(3.0));
  }
  Simulation& held = *sims[0];
  Simulation& free = *sims[1];
  EXPECT_FALSE(held.held());
  ASSERT_TRUE(held.HoldStill());
  EXPECT_TRUE(held.held());
  const Eigen::Isometry3d before = held.T_world_base();
  const Eigen::Vector2d wheels = held.WheelAngles();
  constexpr double kRate_rps = 30.0 * M_PI / 180.0;  // the pitch unit's slew, 2 s to 60 deg
  double max_diff_rad = 0.0;
  for (int k = 1; k <= 1500; ++k) {  // 3 s at 2 ms: slew for 2 s, then hold 60 deg
    const double t = k * held.timestep_s();
    const double setpoint = std::min(t, 2.0) * kRate_rps;
    for (Simulation* s : {&held, &free}) s->SetPitchSetpoint(setpoint, t < 2.0 ? kRate_rps : 0.0);
    held.Step();
    free.Step();
    max_diff_rad = std::max(max_diff_rad, std::abs(held.pitch_rad() - free.pitch_rad()));
  }
  EXPECT_NEAR(held.pitch_rad(), 60.0 * M_PI / 180.0, 0.1 * M_PI / 180.0);
  EXPECT_LT(max_diff_rad, 0.01 * M_PI / 180.0);
  EXPECT_TRUE(held.T_world_base().isApprox(before, 1e-12));
  EXPECT_EQ(held.WheelAngles(), wheels);
  EXPECT_EQ(held.data()->ncon, 0);  // no contact solve while held
  held.Release();
  EXPECT_FALSE(held.held());
  held.StepFor(1.0);
  free.StepFor(1.0);
  EXPECT_GT(held.data()->ncon, 0);
  // The nod's shift of weight moves either robot by ~0.8-1 mm; released, the held one settles to
  // within the creep bound above of where the unheld one is (0.19 mm seen).
  constexpr double kCreep_m = 0.0005;
  EXPECT_LT((held.T_world_base().translation() - free.T_world_base().translation()).norm(),
            kCreep_m);
}

// A robot still driving is not held: HoldStill refuses and the physics goes on.
TEST(Simulation, AMovingRobotIsNotHeld) {
  auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(P3Model::kP3DX));
  SimBase base(*sim);
  ASSERT_TRUE(sim->PlaceRobot(0.0, 0.0, 0.0));
  ASSERT_TRUE(base.Drive(0.3, 0.0, 1.0));
  EXPECT_FALSE(sim->HoldStill());
  EXPECT_FALSE(sim->held());
  const double x = sim->T_world_base().translation().x();
  sim->StepFor(0.2);
  EXPECT_GT(sim->T_world_base().translation().x(), x + 0.02);  // coasting on its ramp down
}

TEST(Simulation, PlacementOutsideTheBoundsIsAClearError) {
  auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(P3Model::kP3AT));
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(9.5, 0.0, 0.0);
  ASSERT_FALSE(pose);
  EXPECT_NE(pose.error().message.find("bounds"), std::string::npos) << pose.error().message;
}

TEST(Simulation, PlacementOffTheWorldIsAClearError) {
  auto sim = Simulation::FromString(kWallWorld, "/tmp", Robot(P3Model::kP3DX));
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(-9.9, 0.0, 0.0);  // half over the floor's edge
  ASSERT_FALSE(pose);
  EXPECT_NE(pose.error().message.find("off the world"), std::string::npos) << pose.error().message;
  EXPECT_FALSE(sim->PlaceRobot(-30.0, 0.0, 0.0));
  EXPECT_TRUE(sim->PlaceRobot(0.0, 0.0, 0.0));  // and the simulation is still usable
}

TEST(Simulation, BrokenWorldThrowsWithThePathAndMujocosMessage) {
  const ScopedTempDir dir("sim_test");
  const std::string path = (dir / "broken.xml").string();
  std::ofstream(path) << "<mujoco><worldbody><geom type=\"sphere\"/></worldbody></mujoco>";
  try {
    Simulation sim(path, Robot(P3Model::kP3DX));
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("size"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Simulation("/nonexistent/world.xml", Robot(P3Model::kP3DX)), std::runtime_error);
}

int CountFiles(const std::string& dir) {
  int n = 0;
  DIR* d = opendir(dir.c_str());
  while (dirent* e = readdir(d)) n += e->d_name[0] != '.';
  closedir(d);
  return n;
}

// MuJoCo 2.2.2's mj_rayHfield lets some vertical rays that run exactly along a grid line fall
// through the surface onto the top of the field's base (here 1375 of the 159 k vertices of a
// smooth 401 x 401 field); placement once took such a ray for the ground and refused a start at
// round coordinates, "a step of 24 m" under a flat footprint. It reads the field's triangles
// instead: a start with its footprint's centre on each such vertex is placed on the surface.
TEST(Simulation, PlacementOnAHeightfieldGridVertexFindsTheSurface) {
  const ScopedTempDir dir("grid_vertex");
  constexpr std::int32_t kN = 401;
  {
    std::ofstream out(dir / "waves.bin", std::ios::binary);
    out.write(reinterpret_cast<const char*>(&kN), sizeof kN);
    out.write(reinterpret_cast<const char*>(&kN), sizeof kN);
    for (int row = 0; row < kN; ++row) {
      for (int col = 0; col < kN; ++col) {  // gentle: at most 9 deg
        const float h =
            static_cast<float>(0.5 + 0.25 * std::sin(0.031 * col) * std::cos(0.027 * row));
        out.write(reinterpret_cast<const char*>(&h), sizeof h);
      }
    }
  }
  const std::filesystem::path world = dir / "waves.xml";
  std::ofstream(world) << R"(<mujoco>
    <asset><hfield name="waves" file="waves.bin" size="20 20 1 1"/></asset>
    <worldbody><geom name="ground" type="hfield" hfield="waves" pos="0 0 -1"/></worldbody>
  </mujoco>)";
  // The vertices where MuJoCo's own vertical ray misses the surface, and the surface there.
  char error[1000] = "";
  std::unique_ptr<mjModel, void (*)(mjModel*)> m(
      mj_loadXML(world.string().c_str(), nullptr, error, sizeof error), mj_deleteModel);
  ASSERT_TRUE(m) << error;
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m.get()), mj_deleteData);
  mj_forward(m.get(), d.get());
  struct Vertex {
    double x, y, surface_z;
  };
  std::vector<Vertex> fallen;
  for (int row = 40; row < kN - 40 && fallen.size() < 6; row += 1) {
    for (int col = 40; col < kN - 40 && fallen.size() < 6; col += 7) {
      const double x = -20.0 + 40.0 * col / (kN - 1), y = -20.0 + 40.0 * row / (kN - 1);
      const double surface = -1.0 + m->hfield_data[row * kN + col];  // size z 1, normalised
      const mjtNum from[3] = {x, y, 10.0}, down[3] = {0, 0, -1};
      const double hit_z = 10.0 - mj_rayHfield(m.get(), d.get(), 0, from, down);
      if (hit_z < surface - 0.01) fallen.push_back({x, y, surface});
    }
  }
  ASSERT_FALSE(fallen.empty()) << "this field no longer shows MuJoCo's fall-through";
  Simulation sim(world.string(), Robot(P3Model::kP3AT));
  const double footprint_x = sim.params().footprint_x_m;
  for (const Vertex& v : fallen) {
    const Result<Eigen::Isometry3d> pose = sim.PlaceRobot(v.x - footprint_x, v.y, 0.0);
    ASSERT_TRUE(pose) << v.x << ", " << v.y << ": " << pose.error().message;
    // base_link (on the ground, REP-105) on the surface, not on the base's top a metre below.
    EXPECT_NEAR(pose->translation().z(), v.surface_z, 0.02) << v.x << ", " << v.y;
  }
}

TEST(Simulation, HeightfieldFileResolvesAgainstTheWorldFolderWhichStaysUntouched) {
  const ScopedTempDir dir("world_dir");
  const std::string world_dir = dir.path().string();
  {
    std::ofstream hf(world_dir + "/flat.bin", std::ios::binary);
    const int32_t rows = 3, cols = 3;
    hf.write(reinterpret_cast<const char*>(&rows), 4)
        .write(reinterpret_cast<const char*>(&cols), 4);
    const float zero[9] = {};
    hf.write(reinterpret_cast<const char*>(zero), sizeof zero);
  }
  std::ofstream(world_dir + "/terrain.xml") << R"(<mujoco>
    <asset><hfield name="ground" file="flat.bin" size="10 10 1 0.1"/></asset>
    <worldbody><geom name="terrain" type="hfield" hfield="ground" pos="0 0 0.2"/></worldbody>
  </mujoco>)";
  const int before = CountFiles(world_dir);
  {
    Simulation sim(world_dir + "/terrain.xml", Robot(P3Model::kP3AT));
    Result<Eigen::Isometry3d> pose = sim.PlaceRobot(1.0, 1.0, 0.0);
    ASSERT_TRUE(pose) << pose.error().message;
    EXPECT_NEAR(pose->translation().z(), 0.2, 0.01);  // hfield at z = 0.2, all heights 0
  }
  EXPECT_EQ(CountFiles(world_dir), before);
}

TEST(ComposeWorldXml, MakesRelativeAssetPathsAbsoluteAndKeepsAbsoluteOnes) {
  const std::string xml = ComposeWorldXml(R"(<mujoco>
    <compiler texturedir="tex"/>
    <asset><hfield name="h" file="a/h.bin" size="1 1 1 1"/>
      <texture name="t" file="t.png"/><mesh name="m" file="/abs/m.stl"/></asset>
    <worldbody/></mujoco>)",
                                          "/w", Robot(P3Model::kP3DX));
  EXPECT_NE(xml.find("file=\"/w/a/h.bin\""), std::string::npos);
  EXPECT_NE(xml.find("texturedir=\"/w/tex\""), std::string::npos);
  EXPECT_NE(xml.find("file=\"t.png\""), std::string::npos);  // under the absolute texturedir
  EXPECT_NE(xml.find("file=\"/abs/m.stl\""), std::string::npos);
  EXPECT_NE(xml.find("<body name=\"robot\""), std::string::npos);
  EXPECT_THROW(ComposeWorldXml("<mujoco></mujoco>", "/w", Robot(P3Model::kP3DX)),
               std::runtime_error);
}

// The contact buffer holds the most contacts the robot's geoms can make (mjMAXCONPAIR each, 4
// pyramidal rows per contact), and no more: MuJoCo 2.2 clears 5 njmax^2 numbers of solver stack
// for every mjData made. A world that sizes the buffer itself keeps its own.
TEST_P(RobotModels, TheContactBufferIsSizedForTheRobotsGeoms) {
  const auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(GetParam()));
  const mjModel* m = sim->model();
  const int robot = mj_name2id(m, mjOBJ_BODY, kRobotBody);
  int robot_geoms = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    int b = m->geom_bodyid[g];
    while (b != 0 && b != robot) b = m->body_parentid[b];
    robot_geoms += b == robot ? 1 : 0;
  }
  EXPECT_GE(robot_geoms, 6);  // tyres or wheels, caster, chassis, laser
  EXPECT_EQ(m->nconmax, mjMAXCONPAIR * robot_geoms);
  EXPECT_EQ(m->njmax, 4 * m->nconmax);
  std::string own(kFlatWorld);
  own.insert(own.rfind("</mujoco>"), "<size nconmax=\"77\" njmax=\"300\"/>\n");
  const auto sized = Simulation::FromString(own, "/tmp", Robot(GetParam()));
  EXPECT_EQ(sized->model()->nconmax, 77);
  EXPECT_EQ(sized->model()->njmax, 300);
}

// The solver's scratch stack grows with rows times dofs (SolverStack), not as MuJoCo's default
// 5 (njmax + nv)^2: a twentieth of it at most here. A world that sizes its stack keeps its own.
TEST_P(RobotModels, TheSolverStackGrowsWithRowsTimesDofsNotRowsSquared) {
  const auto sim = Simulation::FromString(kFlatWorld, "/tmp", Robot(GetParam()));
  const mjModel* m = sim->model();
  const long rows = m->njmax + m->nv;
  EXPECT_EQ(m->nstack, 8 * rows * (m->nv + 10));
  EXPECT_LT(20 * static_cast<double>(m->nstack), 5.0 * rows * rows);
  EXPECT_EQ(sim->data()->nstack, m->nstack);
  std::string own(kFlatWorld);
  own.insert(own.rfind("</mujoco>"), "<size nstack=\"123456\"/>\n");
  EXPECT_EQ(Simulation::FromString(own, "/tmp", Robot(GetParam()))->model()->nstack, 123456);
}

// The most the stack must hold: a full contact buffer over many dofs. 96 loose boxes (576 dofs,
// past MuJoCo's sparse threshold of 60) dropped in six layers onto the floor and each other fill
// the P3-AT's 400 contacts; every step fits the stack (else mju_error throws), with room to spare
// (used 2.8 M of 10.4 M numbers).
TEST(Simulation, AFullContactBufferOverHundredsOfDofsFitsTheSolverStack) {
  std::string boxes;
  for (int k = 0; k < 96; ++k) {
    const double x = 3.0 + 0.25 * (k % 4), y = -0.4 + 0.25 * (k / 4 % 4),
                 z = 0.11 + 0.22 * (k / 16);
    char body[256];
    std::snprintf(body, sizeof body,
                  "<body pos=\"%.2f %.2f %.2f\"><freejoint/>"
                  "<geom type=\"box\" size=\"0.1 0.1 0.1\" mass=\"1\"/></body>\n",
                  x, y, z);
    boxes += body;
  }
  const std::string xml =
      "<mujoco model=\"pile\"><worldbody>"
      "<geom name=\"floor\" type=\"plane\" size=\"10 10 0.1\"/>" +
      boxes + "</worldbody></mujoco>";
  const auto sim = Simulation::FromString(xml, "/tmp", Robot(P3Model::kP3AT));
  ASSERT_GT(sim->model()->nv, 60);
  ASSERT_NO_THROW(sim->Step(500));  // 1 s: the pile falls and settles
  const mjData* d = sim->data();
  EXPECT_GE(d->maxuse_con, sim->model()->nconmax * 3 / 4);  // the buffer (nearly) full
  EXPECT_LT(2 * d->maxuse_stack, d->nstack);
  RecordProperty("maxuse_stack", d->maxuse_stack);
  RecordProperty("maxuse_efc", d->maxuse_efc);
}

}  // namespace
}  // namespace pitchlab::sim

namespace pitchlab::sim {
namespace {

// Every world the build generates loads with the robot, places at its default start and settles,
// and is georeferenced (so run folders carry GeoJSON paths and trajectories).
TEST(Worlds, EveryBuildWorldPlacesBothRobotsAtItsDefaultStart) {
  DIR* dir = opendir(PITCHLAB_WORLDS_DIR);
  if (dir == nullptr) GTEST_SKIP() << "no worlds folder " << PITCHLAB_WORLDS_DIR;
  std::vector<std::string> worlds;
  while (dirent* e = readdir(dir)) {
    const std::string name = e->d_name;
    if (name.size() > 4 && name.substr(name.size() - 4) == ".xml") worlds.push_back(name);
  }
  closedir(dir);
  for (const std::string& name : worlds) {
    for (P3Model model : {P3Model::kP3AT, P3Model::kP3DX}) {
      RobotConfig robot;
      robot.model = model;
      Simulation sim(std::string(PITCHLAB_WORLDS_DIR) + "/" + name, robot);
      const Eigen::Vector3d start = sim.world().default_start.value_or(Eigen::Vector3d::Zero());
      Result<Eigen::Isometry3d> pose = sim.PlaceRobot(start.x(), start.y(), start.z());
      EXPECT_TRUE(pose) << name << ": " << pose.error().message;
      EXPECT_TRUE(sim.TakeWarnings().empty()) << name;
      ASSERT_TRUE(sim.world().geodetic_origin) << name;
      EXPECT_LE(std::abs(sim.world().geodetic_origin->x()), 90.0) << name;
      EXPECT_LE(std::abs(sim.world().geodetic_origin->y()), 180.0) << name;
    }
  }
}

}  // namespace
}  // namespace pitchlab::sim
