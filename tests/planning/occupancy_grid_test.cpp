// map_server occupancy grids (occupancy_grid.hpp): hand-made PGM + YAML read back as the ROS
// map_server documents, the traversability written and read back, and planned on.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"
#include "pitchlab/planning/planner.hpp"
#include "level_layers.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::planning {
namespace {

namespace fs = std::filesystem;

using test_support::ScopedTempDir;

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string Yaml(const std::string& image, const std::string& extra = "") {
  return "image: " + image +
         "\nresolution: 0.5\norigin: [-1.0, 2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
         "free_thresh: 0.196\n" +
         extra;
}

std::int8_t At(const OccupancyGrid& g, int i, int j) { return g.value[g.geometry.Linear({i, j})]; }

TEST(OccupancyGrid, TrinaryPgmReadsAsMapServerDoes) {
  const ScopedTempDir dir("occ_trinary");
  // Top row (north): white, mid grey 205, black; bottom row: 250, 100, 0. p = (255 - x) / 255:
  // 0 free, 0.196 (between the thresholds) unknown, 1 occupied; 0.02 free, 0.61 unknown.
  WriteText(dir / "m.pgm", "P2\n# a comment\n3 2\n255\n254 205 0\n250 100 0\n");
  WriteText(dir / "m.yaml", Yaml("m.pgm"));
  const Result<OccupancyGrid> g = LoadOccupancyGrid((dir / "m.yaml").string());
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_EQ(g->geometry.size_x, 3);
  EXPECT_EQ(g->geometry.size_y, 2);
  EXPECT_EQ(g->geometry.cell_m, 0.5);
  EXPECT_EQ(g->geometry.x_min_m, -1.0);  // the lower-left pixel's corner
  EXPECT_EQ(g->geometry.y_min_m, 2.0);
  EXPECT_EQ(At(*g, 0, 1), 0);
  EXPECT_EQ(At(*g, 1, 1), kOccupancyUnknown);
  EXPECT_EQ(At(*g, 2, 1), kOccupancyLethal);
  EXPECT_EQ(At(*g, 0, 0), 0);
  EXPECT_EQ(At(*g, 1, 0), kOccupancyUnknown);
  EXPECT_EQ(At(*g, 2, 0), kOccupancyLethal);
}

TEST(OccupancyGrid, ScaleNegateAndRawModes) {
  const ScopedTempDir dir("occ_modes");
  // Binary P5. Scale: p = (255 - 150) / 255 = 0.4118 -> 99 (0.4118 - 0.196) / (0.65 - 0.196) =
  // 47.06 -> 47; negate: p = x / 255.
  WriteText(dir / "s.pgm", std::string("P5 2 1 255\n") + char(150) + char(255));
  WriteText(dir / "scale.yaml", Yaml("s.pgm", "mode: scale\n"));
  const Result<OccupancyGrid> scale = LoadOccupancyGrid((dir / "scale.yaml").string());
  ASSERT_TRUE(scale) << scale.error().message;
  EXPECT_EQ(At(*scale, 0, 0), 47);
  EXPECT_EQ(At(*scale, 1, 0), 0);
  std::string negate = Yaml("s.pgm", "mode: scale\n");
  negate.replace(negate.find("negate: 0"), 9, "negate: 1");
  WriteText(dir / "negate.yaml", negate);
  const Result<OccupancyGrid> neg = LoadOccupancyGrid((dir / "negate.yaml").string());
  ASSERT_TRUE(neg) << neg.error().message;
  EXPECT_EQ(At(*neg, 0, 0), 86);                // p = 150 / 255 = 0.588 -> 99 * 0.864 = 85.5
  EXPECT_EQ(At(*neg, 1, 0), kOccupancyLethal);  // p = 1
  WriteText(dir / "r.pgm", "P2 4 1 255 0 37 100 255\n");
  WriteText(dir / "raw.yaml", Yaml(fs::absolute(dir / "r.pgm").string(), "mode: raw\n"));
  const Result<OccupancyGrid> raw = LoadOccupancyGrid((dir / "raw.yaml").string());
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(At(*raw, 0, 0), 0);
  EXPECT_EQ(At(*raw, 1, 0), 37);
  EXPECT_EQ(At(*raw, 2, 0), kOccupancyLethal);
  EXPECT_EQ(At(*raw, 3, 0), kOccupancyUnknown);
}

TEST(OccupancyGrid, BadFilesNameTheFileAndTheLine) {
  const ScopedTempDir dir("occ_bad");
  WriteText(dir / "ok.pgm", "P2 2 2 255 0 0 0 0\n");
  const std::string yaml = (dir / "m.yaml").string();
  const struct {
    std::string yaml, pgm, where, what;
  } cases[] = {
      {"resolution: 0.5\n", "", yaml + ":1:", "missing key 'image'"},
      {Yaml("ok.pgm", "colour: red\n"), "", yaml + ":7:", "unknown key 'colour'"},
      {Yaml("ok.pgm", "resolution: 1\n"), "", yaml + ":7:", "given twice (lines 2 and 7)"},
      {Yaml("ok.pgm", "mode: fancy\n"), "", yaml + ":7:", "trinary, scale or raw"},
      {"image: ok.pgm\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n"
       "free_thresh: 0.196\n",
       "", yaml + ":2:", "positive"},
      {"image: ok.pgm\nresolution: 1\norigin: [0, 0, 0.5]\nnegate: 0\noccupied_thresh: 0.65\n"
       "free_thresh: 0.196\n",
       "", yaml + ":3:", "rotated grid"},
      {"image: ok.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.1\n"
       "free_thresh: 0.196\n",
       "", yaml + ":6:", "0 <= free_thresh < occupied_thresh"},
      {"image: [ok.pgm\n", "", yaml + ":", "not valid YAML"},
      {Yaml("b.pgm"), "P6 2 2 255\n", "b.pgm:1:", "not a PGM image"},
      {Yaml("b.pgm"), "P2\n2 2\n255\n0 0\n0\n", "b.pgm:5:", "the image ends after 3 of 4"},
      {Yaml("b.pgm"), "P2\n2 1\n255\n0 256\n", "b.pgm:4:", "pixel '256' is not 0..255"},
      {Yaml("b.pgm"), std::string("P5\n2 2\n255\n") + char(0), "b.pgm:3:", "ends after 1 of 4"},
      {Yaml("b.pgm"), "P2\n0 2\n255\n", "b.pgm:2:", "PGM width '0'"},
  };
  for (const auto& c : cases) {
    WriteText(yaml, c.yaml);
    fs::remove(dir / "b.pgm");
    if (!c.pgm.empty()) WriteText(dir / "b.pgm", c.pgm);
    const Result<OccupancyGrid> g = LoadOccupancyGrid(yaml);
    ASSERT_FALSE(g) << c.yaml;
    EXPECT_NE(g.error().message.find(c.where), std::string::npos) << g.error().message;
    EXPECT_NE(g.error().message.find(c.what), std::string::npos) << g.error().message;
  }
  WriteText(yaml, Yaml("absent.pgm"));
  const Result<OccupancyGrid> absent = LoadOccupancyGrid(yaml);
  ASSERT_FALSE(absent);
  EXPECT_EQ(absent.error().code, Error::Code::kNotFound);
  EXPECT_NE(absent.error().message.find("absent.pgm: cannot open"), std::string::npos);
}

// Layers of a 6 x 4 grid of 0.5 m cells: level ground at 0 with a 0.3 m block on cell (3, 2),
// cell (0, 3) unknown, cell (5, 0) on a 10 deg slope.
mapping::ElevationLayers SmallLayers() {
  mapping::ElevationLayers L = test_support::LevelLayers({0, 0, 0.5, 6, 4});
  L.plane_residual.assign(L.geometry.cell_count(), NAN);
  const std::size_t block = L.geometry.Linear({3, 2}), unknown = L.geometry.Linear({0, 3});
  L.mean_z[block] = L.min_z[block] = L.max_z[block] = 0.3f;
  L.state[unknown] = mapping::CellState::kUnknown;
  L.phi_x[L.geometry.Linear({5, 0})] = static_cast<float>(10 * M_PI / 180);
  return L;
}

TEST(OccupancyGrid, TraversabilityWrittenAndReadBackKeepsItsClassesAndCosts) {
  PlannerConfig config;
  config.robot.width_m = 0;  // no footprint margin: the classes as they are
  const TraversabilityGrid T = BuildTraversability(SmallLayers(), config);
  const OccupancyGrid occupancy = ToOccupancy(T);
  const mapping::GridGeometry& g = T.geometry;
  EXPECT_EQ(occupancy.value[g.Linear({3, 2})], kOccupancyLethal);  // the block's top: a step
  EXPECT_EQ(occupancy.value[g.Linear({0, 3})], kOccupancyUnknown);
  EXPECT_EQ(occupancy.value[g.Linear({0, 0})], 0);  // level, smooth: no cost
  // 10 deg along x costs W_phix * 0.1745; the full scale is 10 * 0.089 / 2 + 2 * atan(0.35).
  const double full = 10 * 0.089 / 2 + 2 * std::atan(0.35);
  EXPECT_NEAR(FullScaleCost(config), full, 1e-12);
  EXPECT_EQ(occupancy.value[g.Linear({5, 0})], std::lround(99 * (10 * M_PI / 180) / full));

  const ScopedTempDir dir("occ_roundtrip");
  const fs::path yaml = dir / "traversability.yaml";
  ASSERT_TRUE(WriteOccupancyGrid(occupancy, yaml.string()));
  EXPECT_TRUE(fs::exists(yaml.parent_path() / "traversability.pgm"));
  const Result<OccupancyGrid> back = LoadOccupancyGrid(yaml.string());
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->geometry.SameAs(g));
  EXPECT_EQ(back->value, occupancy.value);
}

// A 20 x 10 grid of 0.1 m cells, free but for a wall at column 10 with a gap in rows `gap_lo`
// to 9 (the top rows).
OccupancyGrid Wall(int gap_lo) {
  OccupancyGrid g;
  g.geometry = {0, 0, 0.1, 20, 10};
  g.value.assign(g.geometry.cell_count(), 0);
  for (int j = 0; j < gap_lo; ++j) g.value[g.geometry.Linear({10, j})] = kOccupancyLethal;
  return g;
}

TEST(OccupancyGrid, PlansAroundObstaclesAndThroughGapsTheRobotFits) {
  PlannerConfig point;
  point.robot.width_m = 0;
  // No wall: the straight line, 16 cells of 0.1 m.
  const auto straight = PlanPath(BuildTraversability(Wall(0), point), {0.25, 0.25}, {1.85, 0.25},
                                 Algorithm::kDijkstra);
  ASSERT_TRUE(straight) << straight.error().message;
  EXPECT_NEAR(straight->length_m, 1.6, 1e-6);
  EXPECT_NEAR(straight->cost, 1.6, 1e-5);  // free cells cost their length only
  // A wall up to row 6: the path climbs to row 7 at the wall; the shortest 8-connected detour.
  const TraversabilityGrid T = BuildTraversability(Wall(7), point);
  const auto around = PlanPath(T, {0.25, 0.25}, {1.85, 0.25}, Algorithm::kAStar);
  ASSERT_TRUE(around) << around.error().message;
  for (const mapping::CellIndex& c : around->cells)
    EXPECT_NE(T.blocked[T.geometry.Linear(c)], Blocked::kOccupied);
  // From row 2 to row 7 and back over 16 columns: 5 diagonal moves each way, 6 straight.
  EXPECT_NEAR(around->length_m, 0.1 * (10 * M_SQRT2 + 6), 1e-5);
  // The P3-AT (0.497 m wide) does not fit the 0.3 m gap.
  const auto p3at = PlanPath(BuildTraversability(Wall(7), PlannerConfig{}), {0.45, 0.45},
                             {1.55, 0.45}, Algorithm::kAStar);
  ASSERT_FALSE(p3at);
  EXPECT_EQ(p3at.error().reason, NoPath::Reason::kDisconnected);
}

TEST(OccupancyGrid, GreyCellsCostWhatTheirLevelSays) {
  PlannerConfig point;
  point.robot.width_m = 0;
  OccupancyGrid g = Wall(0);
  for (int i = 0; i < 20; ++i) g.value[g.geometry.Linear({i, 2})] = 99;  // a grey row 2
  const TraversabilityGrid T = BuildTraversability(g, point);
  const auto p = PlanPath(T, {0.25, 0.25}, {1.85, 0.25}, Algorithm::kDijkstra);
  ASSERT_TRUE(p) << p.error().message;
  // From and to the grey row: a grey cell costs more (1.56) than stepping off the row and back
  // (2 diagonals for 2 straight moves: 0.083 more), so only the goal's grey cell is entered.
  EXPECT_NEAR(p->parts.occupancy, FullScaleCost(point), 1e-5);
  EXPECT_NEAR(p->length_m, 0.1 * (14 + 2 * M_SQRT2), 1e-5);
  EXPECT_NEAR(p->cost, p->parts.Total(), 1e-4);
  // Below row 2 the same line costs its length only: the planner takes it.
  const auto q = PlanPath(T, {0.25, 0.15}, {1.85, 0.15}, Algorithm::kDijkstra);
  ASSERT_TRUE(q);
  EXPECT_NEAR(q->parts.occupancy, 0.0, 1e-9);
}

}  // namespace
}  // namespace pitchlab::planning
