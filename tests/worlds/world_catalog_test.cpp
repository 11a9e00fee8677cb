// Every built-in world loads on its own in MuJoCo, says what it is, and is safe to put a robot in.
#include <cmath>
#include <set>
#include <stdexcept>

#include "pitchlab/worlds/world_catalog.hpp"
#include "pitchlab/worlds/world_metadata.hpp"
#include "test_support.hpp"

namespace pitchlab::worlds {
namespace {

using test::DataPtr;
using test::LoadModel;
using test::ModelPtr;
using test::SurfaceHeight;

constexpr double kFlatStart_m = 0.02;  // height spread allowed under a robot at its start
const std::filesystem::path kWorldsDir = PITCHLAB_WORLDS_DIR;

}  // namespace

// Readable parameter names in gtest output.
void PrintTo(const CatalogEntry& entry, std::ostream* os) { *os << entry.name; }

namespace {

class BuiltinWorld : public ::testing::TestWithParam<CatalogEntry> {
 protected:
  void SetUp() override {
    model_ = LoadModel(ResolveWorld(GetParam().name, kWorldsDir));
    ASSERT_TRUE(model_);
    data_.reset(mj_makeData(model_.get()));
    mj_forward(model_.get(), data_.get());
  }
  ModelPtr model_;
  DataPtr data_;
};

TEST_P(BuiltinWorld, LoadsWithDescriptionBoundsAndAFlatFreeStart) {
  const WorldMetadata meta = ReadWorldMetadata(model_.get());
  EXPECT_FALSE(meta.description.empty());
  const Bounds2d& b = meta.bounds;
  const StartPose& s = meta.default_start;
  EXPECT_TRUE(s.x_m > b.x_min_m && s.x_m < b.x_max_m && s.y_m > b.y_min_m && s.y_m < b.y_max_m);
  // The robot's footprint (about 0.6 m square) at the start: the top-most surface is one level,
  // so nothing stands there and the ground is flat.
  const double z0 = SurfaceHeight(model_.get(), data_.get(), s.x_m, s.y_m);
  ASSERT_FALSE(std::isnan(z0));
  for (double dx : {-0.3, 0.0, 0.3}) {
    for (double dy : {-0.3, 0.0, 0.3}) {
      EXPECT_NEAR(SurfaceHeight(model_.get(), data_.get(), s.x_m + dx, s.y_m + dy), z0,
                  kFlatStart_m)
          << GetParam().name << " start offset " << dx << ", " << dy;
    }
  }
}

// Every built-in world is a mission: `run` and `bench` drive from its default start to this goal.
TEST_P(BuiltinWorld, NamesADefaultGoalOnItsGroundAwayFromTheStart) {
  const WorldMetadata meta = ReadWorldMetadata(model_.get());
  ASSERT_TRUE(meta.default_goal) << GetParam().name;
  const GoalPoint& g = *meta.default_goal;
  const Bounds2d& b = meta.bounds;
  EXPECT_TRUE(g.x_m > b.x_min_m && g.x_m < b.x_max_m && g.y_m > b.y_min_m && g.y_m < b.y_max_m);
  EXPECT_FALSE(std::isnan(SurfaceHeight(model_.get(), data_.get(), g.x_m, g.y_m)));
  // Farther than the run's goal tolerance (0.5 m) plus one stop's drive (4 m): at least one
  // scan-plan-drive cycle before the goal.
  constexpr double kMinMission_m = 4.5;
  EXPECT_GT(std::hypot(g.x_m - meta.default_start.x_m, g.y_m - meta.default_start.y_m),
            kMinMission_m);
}

TEST_P(BuiltinWorld, GroundCoversItsBoundsWithFiniteVisibleGeoms) {
  const WorldMetadata meta = ReadWorldMetadata(model_.get());
  const Bounds2d& b = meta.bounds;
  for (double x = b.x_min_m; x <= b.x_max_m; x += (b.x_max_m - b.x_min_m) / 23.0) {
    for (double y = b.y_min_m; y <= b.y_max_m; y += (b.y_max_m - b.y_min_m) / 23.0) {
      EXPECT_FALSE(std::isnan(SurfaceHeight(model_.get(), data_.get(), x, y)))
          << "no ground under " << x << ", " << y;
    }
  }
  for (int g = 0; g < model_->ngeom; ++g) {
    EXPECT_GT(model_->geom_rgba[4 * g + 3], 0.0f) << "alpha 0 hides geom " << g << " from mj_ray";
    if (model_->geom_type[g] == mjGEOM_PLANE) {
      EXPECT_GT(model_->geom_size[3 * g], 0.0) << "infinite plane " << g;
    }
    EXPECT_TRUE(model_->geom_contype[g] != 0 && model_->geom_conaffinity[g] != 0);
  }
}

TEST_P(BuiltinWorld, HasNoRobotAndNoNameTheRobotCouldClashWith) {
  for (mjtObj type : {mjOBJ_BODY, mjOBJ_GEOM, mjOBJ_JOINT, mjOBJ_SITE}) {
    int count = type == mjOBJ_BODY    ? model_->nbody
                : type == mjOBJ_GEOM  ? model_->ngeom
                : type == mjOBJ_JOINT ? model_->njnt
                                      : model_->nsite;
    for (int i = 0; i < count; ++i) {
      const char* name = mj_id2name(model_.get(), type, i);
      if (name) EXPECT_NE(std::string(name).rfind("robot", 0), 0u) << name;
    }
  }
  EXPECT_EQ(model_->nu, 0);
}

INSTANTIATE_TEST_SUITE_P(AllWorlds, BuiltinWorld, ::testing::ValuesIn(BuiltinWorlds()),
                         [](const auto& info) { return info.param.name; });

TEST(WorldCatalog, ListsTheSixWorldsInOrder) {
  std::string names;
  for (const auto& entry : BuiltinWorlds()) names += entry.name + " ";
  EXPECT_EQ(names, "office cluttered corridor urban terrain gully ");
}

TEST(WorldCatalog, UnknownNameListsTheKnownWorlds) {
  try {
    ResolveWorld("moon", kWorldsDir);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown world 'moon'; known: office, cluttered, corridor, urban, terrain, gully");
  }
}

TEST(WorldCatalog, AnyExistingXmlPathIsAWorldAndAMissingOneIsAnError) {
  const auto office = kWorldsDir / "office.xml";
  EXPECT_EQ(ResolveWorld(office.string(), "/nonexistent"), office);
  EXPECT_THROW(ResolveWorld((kWorldsDir / "nope.xml").string(), kWorldsDir), std::invalid_argument);
  EXPECT_THROW(ResolveWorld("office", "/nonexistent"), std::invalid_argument);
}

ModelPtr LoadString(const std::string& xml) {
  const test::ScopedTempDir dir("inline");
  test::WriteText(dir.path() / "w.xml", xml);
  return LoadModel(dir.path() / "w.xml");
}

TEST(WorldMetadata, AnyMjcfIsAWorldWithDefaults) {
  auto model = LoadString(R"(<mujoco><worldbody>
      <geom type="box" pos="3 4 -0.5" size="5 5 0.5"/></worldbody></mujoco>)");
  ASSERT_TRUE(model);
  const WorldMetadata meta = ReadWorldMetadata(model.get());
  EXPECT_TRUE(meta.description.empty());
  EXPECT_FALSE(meta.geodetic_origin);
  EXPECT_LT(meta.bounds.x_min_m, meta.bounds.x_max_m);
  EXPECT_EQ(meta.default_start.x_m, 0.0);
}

TEST(WorldMetadata, MalformedBoundsNameTheField) {
  auto model = LoadString(R"(<mujoco><worldbody><geom type="sphere" size="1"/></worldbody>
      <custom><numeric name="pitchlab:bounds" data="1 2 3"/></custom></mujoco>)");
  ASSERT_TRUE(model);
  try {
    ReadWorldMetadata(model.get());
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pitchlab:bounds"), std::string::npos) << e.what();
  }
}

TEST(WorldMetadata, YawIsStoredInDegreesAndReadInRadians) {
  auto model = LoadString(R"(<mujoco><worldbody><geom type="sphere" size="1"/></worldbody>
      <custom><numeric name="pitchlab:default_start" data="1 2 90"/></custom></mujoco>)");
  ASSERT_TRUE(model);
  EXPECT_NEAR(ReadWorldMetadata(model.get()).default_start.yaw_rad, M_PI / 2, 1e-12);
}

struct Loaded {
  ModelPtr model;
  DataPtr data;
};
Loaded LoadWorld(const std::string& name) {
  Loaded w{LoadModel(ResolveWorld(name, kWorldsDir)), nullptr};
  if (w.model) {
    w.data.reset(mj_makeData(w.model.get()));
    mj_forward(w.model.get(), w.data.get());
  }
  return w;
}

TEST(Worlds, UrbanHasCurbsADitchAndStairsBelowStreetLevel) {
  Loaded w = LoadWorld("urban");
  ASSERT_TRUE(w.model);
  auto h = [&](double x, double y) { return SurfaceHeight(w.model.get(), w.data.get(), x, y); };
  const double curb_m = h(5.0, 6.0) - h(3.0, 6.0);  // block edge at x = 4
  EXPECT_TRUE(curb_m >= 0.12 && curb_m <= 0.15) << curb_m;
  EXPECT_LT(h(-20.0, 16.6), -0.5) << "ditch";
  EXPECT_LT(h(18.0, -20.0), -1.0) << "sunken court";
  double previous = h(18.0, -11.9);
  for (double y = -12.15; y > -14.0; y -= 0.3) {  // each tread one riser lower
    EXPECT_NEAR(previous - h(18.0, y), 0.15, 1e-6) << "step at y " << y;
    previous = h(18.0, y);
  }
}

TEST(Worlds, ClutteredHasMovableBoxesAndEveryPrimitiveType) {
  Loaded w = LoadWorld("cluttered");
  ASSERT_TRUE(w.model);
  int free_joints = 0;
  for (int j = 0; j < w.model->njnt; ++j) free_joints += w.model->jnt_type[j] == mjJNT_FREE;
  EXPECT_GE(free_joints, 3);
  std::set<int> types(w.model->geom_type, w.model->geom_type + w.model->ngeom);
  for (int t : {mjGEOM_BOX, mjGEOM_CYLINDER, mjGEOM_CAPSULE, mjGEOM_SPHERE, mjGEOM_ELLIPSOID}) {
    EXPECT_TRUE(types.count(t)) << "geom type " << t;
  }
}

TEST(Worlds, OfficeDoorsAreAtLeastNinetyCentimetresWide) {
  Loaded w = LoadWorld("office");
  ASSERT_TRUE(w.model);
  // Walk along the corridor's north and south walls at 1 m height, horizontally through them.
  for (double wall_y : {1.0, -1.0}) {
    int open_run = 0, doors = 0;
    for (double x = -9.9; x <= 9.9; x += 0.01) {
      const mjtNum from[3] = {x, 0.0, 1.0};
      const mjtNum dir[3] = {0.0, wall_y > 0 ? 1.0 : -1.0, 0.0};
      int geom = -1;
      const double d = mj_ray(w.model.get(), w.data.get(), from, dir, nullptr, 1, -1, &geom);
      const bool open = d < 0 || d > 1.2;
      if (open) {
        ++open_run;
      } else if (open_run > 0) {
        doors += open_run >= 90;
        EXPECT_GE(open_run, 90) << "opening ending at x " << x;
        open_run = 0;
      }
    }
    EXPECT_GE(doors, 2) << "wall at y " << wall_y;
  }
}

TEST(Worlds, GullysDefaultGoalLiesDownhillFromItsStart) {
  Loaded w = LoadWorld("gully");
  ASSERT_TRUE(w.model);
  const WorldMetadata meta = ReadWorldMetadata(w.model.get());
  ASSERT_TRUE(meta.default_goal);
  const double start_z =
      SurfaceHeight(w.model.get(), w.data.get(), meta.default_start.x_m, meta.default_start.y_m);
  const double goal_z =
      SurfaceHeight(w.model.get(), w.data.get(), meta.default_goal->x_m, meta.default_goal->y_m);
  // The DEM puts the goal 1.0 m below the start (GullyConfig::default_goal); half of that is far
  // above the relief's rocks and cracks and still says the mission descends into the gully.
  EXPECT_LT(goal_z, start_z - 0.5);
}

TEST(Worlds, GullyIsPlacedAtItsTrueGeodeticOrigin) {
  Loaded w = LoadWorld("gully");
  ASSERT_TRUE(w.model);
  const WorldMetadata meta = ReadWorldMetadata(w.model.get());
  ASSERT_TRUE(meta.geodetic_origin);
  constexpr double kOriginTolerance_deg = 0.02;  // about 2 km, the DEM is 130 x 270 m
  EXPECT_NEAR(meta.geodetic_origin->latitude_deg, 39.56, kOriginTolerance_deg);
  EXPECT_NEAR(meta.geodetic_origin->longitude_deg, -104.30, kOriginTolerance_deg);
  EXPECT_NEAR(meta.geodetic_origin->height_m, 1700.0, 30.0);
}

}  // namespace
}  // namespace pitchlab::worlds
