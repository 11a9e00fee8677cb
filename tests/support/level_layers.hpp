#pragma once
// Elevation layers made by hand for tests that need a map whose every cell is known: level,
// observed ground at z = 0 over a grid, to be edited cell by cell into the scene under test.

#include <limits>

#include "pitchlab/mapping/elevation_layers.hpp"

namespace pitchlab::test_support {

/// Every cell of `g` observed (10 points), at height 0, level (inclination 0), smooth, with no
/// ray passing over it; the optional layers (plane residual, point spans) left empty.
inline mapping::ElevationLayers LevelLayers(const mapping::GridGeometry& g) {
  mapping::ElevationLayers L;
  L.geometry = g;
  const std::size_t n = g.cell_count();
  L.state.assign(n, mapping::CellState::kObserved);
  L.count.assign(n, 10);
  for (auto* v : {&L.mean_z, &L.min_z, &L.max_z, &L.roughness, &L.phi_x, &L.phi_y})
    v->assign(n, 0.0f);
  L.clearance_z.assign(n, std::numeric_limits<float>::infinity());
  return L;
}

}  // namespace pitchlab::test_support
