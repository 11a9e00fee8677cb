#pragma once
// Bit-for-bit comparisons of layers and traversability grids (NaN cells included), for the tests
// that two ways of making one (a reused buffer and a fresh one, a parallel pass and one thread)
// give the same grid.

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::planning::same_grids {

template <typename T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

inline void ExpectSameLayers(const mapping::ElevationLayers& a, const mapping::ElevationLayers& b) {
  EXPECT_EQ(a.geometry.size_x, b.geometry.size_x);
  EXPECT_EQ(a.geometry.size_y, b.geometry.size_y);
  EXPECT_TRUE(SameBits(a.state, b.state));
  EXPECT_TRUE(SameBits(a.count, b.count));
  EXPECT_TRUE(SameBits(a.mean_z, b.mean_z));
  EXPECT_TRUE(SameBits(a.min_z, b.min_z));
  EXPECT_TRUE(SameBits(a.max_z, b.max_z));
  EXPECT_TRUE(SameBits(a.roughness, b.roughness));
  EXPECT_TRUE(SameBits(a.phi_x, b.phi_x));
  EXPECT_TRUE(SameBits(a.phi_y, b.phi_y));
  EXPECT_TRUE(SameBits(a.clearance_z, b.clearance_z));
  EXPECT_TRUE(SameBits(a.plane_residual, b.plane_residual));
}

inline void ExpectSameTraversability(const TraversabilityGrid& a, const TraversabilityGrid& b) {
  EXPECT_EQ(a.geometry.size_x, b.geometry.size_x);
  EXPECT_EQ(a.geometry.size_y, b.geometry.size_y);
  EXPECT_TRUE(SameBits(a.z_m, b.z_m));
  EXPECT_TRUE(SameBits(a.enter_cost, b.enter_cost));
  EXPECT_TRUE(SameBits(a.roughness_m, b.roughness_m));
  EXPECT_TRUE(SameBits(a.phi_x_rad, b.phi_x_rad));
  EXPECT_TRUE(SameBits(a.phi_y_rad, b.phi_y_rad));
  EXPECT_TRUE(SameBits(a.blocked, b.blocked));
  EXPECT_TRUE(SameBits(a.moves, b.moves));
  EXPECT_TRUE(SameBits(a.move_cost, b.move_cost));
  EXPECT_EQ(a.min_straight_cost, b.min_straight_cost);
  EXPECT_EQ(a.min_diagonal_cost, b.min_diagonal_cost);
  EXPECT_EQ(a.max_edge_cost, b.max_edge_cost);
  EXPECT_EQ(a.min_enter_cost, b.min_enter_cost);
}

}  // namespace pitchlab::planning::same_grids
