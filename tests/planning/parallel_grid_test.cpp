// The map's layers and the planner's grid are computed row blocks at a time on the machine's cores
// (mapping::ParallelFor): the grids must be, bit for bit, the ones one thread makes.

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/parallel_for.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "same_grids.hpp"

namespace pitchlab::planning {
namespace {

// 240 x 200 cells of 0.1 m with every kind of cell: rolling ground, a slope too steep, a 0.3 m
// step, a pit, cells seen by one point and holes never seen.
mapping::ElevationMap VariedMap() {
  mapping::ElevationMap map(mapping::GridGeometry{0, 0, 0.1, 240, 200});
  std::vector<Eigen::Vector3f> pts;
  unsigned state = 12345;
  // Rougher with every row: the cheapest and the dearest moves lie in the first and the last
  // rows' blocks, so a block's extremes lost in the combining would show.
  const auto noise = [&state](int row) {
    state = state * 1664525u + 1013904223u;
    return ((state >> 8) / double(1 << 24) - 0.5) * (0.002 + 0.0002 * row);
  };
  for (int j = 0; j < 200; ++j) {
    for (int i = 0; i < 240; ++i) {
      if (j >= 80 && j < 120 && (i / 7 + j / 5) % 11 == 0) continue;  // holes, mid-map
      const double x = (i + 0.5) * 0.1, y = (j + 0.5) * 0.1;
      double z = 0.2 * std::sin(0.3 * x) * std::cos(0.25 * y);
      if (x > 18) z += 0.6 * (x - 18);               // too steep beyond x = 18 m
      if (y > 14 && x < 10) z += 0.3;                // a step
      if (std::hypot(x - 6, y - 6) < 1.0) z -= 1.0;  // a pit
      const int n = (i + j) % 13 == 0 ? 1 : 4;       // some cells hold one point
      for (int p = 0; p < n; ++p) {
        pts.emplace_back(x + 0.03 * (p % 2) - 0.015, y + 0.03 * (p / 2) - 0.015, z + noise(j));
      }
    }
  }
  (void)map.InsertPoints(pts.data(), pts.size());
  return map;
}

TEST(ParallelGrid, TheLayersAreThoseOfOneThread) {
  const mapping::ElevationMap map = VariedMap();
  mapping::ElevationLayers serial, parallel;
  {
    const mapping::SerialLoops alone;
    mapping::ComputeLayersInto(map, mapping::LayerConfig{}, serial);
  }
  mapping::ComputeLayersInto(map, mapping::LayerConfig{}, parallel);
  same_grids::ExpectSameLayers(serial, parallel);
  int steep = 0, unknown = 0;
  for (std::size_t k = 0; k < serial.state.size(); ++k) {
    unknown += serial.state[k] == mapping::CellState::kUnknown;
    steep += std::abs(serial.phi_x[k]) > 0.5f;
  }
  EXPECT_GT(unknown, 500);  // the map has what the passes decide on
  EXPECT_GT(steep, 1000);
}

TEST(ParallelGrid, TheTraversabilityIsThatOfOneThread) {
  const mapping::ElevationLayers layers = mapping::ComputeLayers(VariedMap());
  PlannerConfig config;
  config.clearance_m = 0.5, config.clearance_cost = 1.0;  // as the runs price it
  TraversabilityGrid serial, parallel;
  {
    const mapping::SerialLoops alone;
    BuildTraversabilityInto(layers, config, serial);
  }
  BuildTraversabilityInto(layers, config, parallel);
  same_grids::ExpectSameTraversability(serial, parallel);
  int kinds[8] = {};
  for (const Blocked b : serial.blocked) ++kinds[static_cast<int>(b) & 7];
  int present = 0;
  for (const int n : kinds) present += n > 0;
  EXPECT_GE(present, 4);  // free, near a hazard, too steep, step or drop at least
}

}  // namespace
}  // namespace pitchlab::planning
