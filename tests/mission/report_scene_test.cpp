#include "report_scene.hpp"

#include <cmath>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace pitchlab::mission {
namespace {

std::string FromBase64(const std::string& text) {
  static const std::string kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned bits = 0;
  int n = 0;
  for (char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | static_cast<unsigned>(kAlphabet.find(c));
    n += 6;
    if (n >= 8) {
      n -= 8;
      out += static_cast<char>((bits >> n) & 0xff);
    }
  }
  return out;
}

int Int16At(const std::string& bytes, std::size_t k) {
  return static_cast<std::int16_t>(static_cast<std::uint8_t>(bytes[2 * k]) |
                                   (static_cast<std::uint8_t>(bytes[2 * k + 1]) << 8));
}

TEST(DecimateCloud, KeepsEveryKthPointUpToTheLimit) {
  mapping::PointCloud cloud;
  for (int i = 0; i < 1001; ++i) cloud.emplace_back(float(i), 0, 0);
  const auto kept = DecimateCloud(cloud, 100);
  EXPECT_LE(kept.size(), 100u);
  EXPECT_GE(kept.size(), 90u);
  EXPECT_EQ(kept[1].x() - kept[0].x(), 11.0f);  // k = ceil(1001 / 100)
  EXPECT_EQ(DecimateCloud(cloud, 5000).size(), 1001u);
}

TEST(SceneJson, PointsComeBackWithinTheQuantum) {
  Scene3D scene;
  scene.cloud_m = {{-3.2f, 7.1f, 0.05f}, {12.0f, -4.0f, 2.5f}, {0.0f, 0.0f, 0.0f}};
  scene.true_m = {{0, 0, 0.1}, {1, 0, 0.1}};
  const nlohmann::json j = nlohmann::json::parse(SceneJson(scene));
  const std::string xyz = FromBase64(j["cloud"]["xyz"].get<std::string>());
  ASSERT_EQ(xyz.size(), 3u * 3u * 2u);
  const double q = j["cloud"]["scale"].get<double>();
  EXPECT_LE(q, 0.001);  // 16 bits over a 16 m span: finer than the 1 mm floor
  for (std::size_t p = 0; p < 3; ++p) {
    for (int a = 0; a < 3; ++a) {
      const double v =
          j["cloud"]["origin"][a].get<double>() + (Int16At(xyz, 3 * p + a) + 32767) * q;
      EXPECT_NEAR(v, scene.cloud_m[p][a], q) << p << "," << a;
    }
  }
  EXPECT_EQ(j["true"].size(), 2u);
}

TEST(BuildSurface, KeepsHeightsUnknownCellsAndTraversabilityColours) {
  mapping::ElevationLayers layers;
  layers.geometry = mapping::GridGeometry::FromArea(0, 0, 1.0, 1.0, 0.1);  // 10 x 10 cells
  const std::size_t n = layers.geometry.cell_count();
  layers.state.assign(n, mapping::CellState::kObserved);
  layers.mean_z.assign(n, 0.25f);
  layers.state[layers.geometry.Linear({3, 4})] = mapping::CellState::kUnknown;
  planning::TraversabilityGrid grid;
  grid.geometry = layers.geometry;
  grid.blocked.assign(n, planning::Blocked::kFree);
  grid.z_m.assign(n, 0.25f);
  grid.enter_cost.assign(n, 1.0f);
  grid.blocked[layers.geometry.Linear({5, 5})] = planning::Blocked::kStep;
  const SceneSurface s = BuildSurface(layers, grid, {{0.2, 0.2}, {0.75, 0.95}});
  ASSERT_EQ(s.nx, 6);  // cells 2..7
  ASSERT_EQ(s.ny, 8);  // cells 2..9
  EXPECT_NEAR(s.x0_m, 0.2, 1e-9);
  EXPECT_FLOAT_EQ(s.z_m[0], 0.25f);
  EXPECT_TRUE(std::isnan(s.z_m[(4 - 2) * s.nx + (3 - 2)]));
  const std::size_t step = (5 - 2) * s.nx + (5 - 2);
  EXPECT_EQ(s.rgb[3 * step], 200);  // RenderTraversability's step red
  EXPECT_EQ(s.rgb[3 * step + 1], 20);
  // The JSON marks the unknown cell with the sentinel.
  Scene3D scene;
  scene.surface = s;
  const nlohmann::json j = nlohmann::json::parse(SceneJson(scene));
  const std::string z = FromBase64(j["surface"]["z"].get<std::string>());
  EXPECT_EQ(Int16At(z, (4 - 2) * s.nx + (3 - 2)), -32768);
  EXPECT_NE(Int16At(z, 0), -32768);
}

}  // namespace
}  // namespace pitchlab::mission
