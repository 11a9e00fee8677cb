#include "pitchlab/mission/traversability_image.hpp"

#include <array>
#include <cmath>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

using planning::Blocked;

std::array<int, 3> Pixel(const mapping::RgbImage& img, int x, int y) {
  const std::size_t o = (static_cast<std::size_t>(y) * img.width + x) * 3;
  return {img.rgb[o], img.rgb[o + 1], img.rgb[o + 2]};
}

// One row of six cells, one per kind, 2 pixels a cell.
TEST(RenderTraversability, EachKindOfCellHasItsColourNorthUp) {
  planning::TraversabilityGrid T;
  T.geometry = mapping::GridGeometry::FromArea(0.0, 0.0, 0.6, 0.2, 0.1);  // 6 x 2 cells
  const std::size_t n = T.geometry.cell_count();
  T.blocked.assign(n, Blocked::kFree);
  T.z_m.assign(n, 0.0f);
  T.enter_cost.assign(n, 1.0f);
  T.enter_cost[1] = 3.0f;  // a costlier free cell
  T.blocked[2] = Blocked::kStep;
  T.blocked[3] = Blocked::kTooSteep;
  T.blocked[4] = Blocked::kDrop;
  T.blocked[5] = Blocked::kNearHazard;
  T.z_m[6] = NAN;  // row 1: an unknown cell under the penalise policy (free, no height)
  mapping::ImageOptions options;
  options.pixels_per_cell = 2;
  const mapping::RgbImage img = RenderTraversability(T, options);
  ASSERT_EQ(img.width, 12);
  ASSERT_EQ(img.height, 4);
  // Row 0 (south) is the bottom of the picture.
  const std::array<int, 3> cheap = Pixel(img, 0, 3), dear = Pixel(img, 2, 3);
  EXPECT_GT(cheap[1], cheap[0]);  // green
  EXPECT_LT(dear[1], cheap[1]);   // darker where entering costs more
  EXPECT_EQ(Pixel(img, 4, 3), (std::array<int, 3>{200, 20, 20}));
  EXPECT_EQ(Pixel(img, 6, 3), (std::array<int, 3>{245, 140, 0}));
  EXPECT_EQ(Pixel(img, 8, 3), (std::array<int, 3>{220, 0, 220}));
  EXPECT_EQ(Pixel(img, 10, 3), (std::array<int, 3>{240, 175, 175}));
  const std::array<int, 3> unknown = Pixel(img, 0, 0);  // row 1, the top
  EXPECT_EQ(unknown[0], unknown[1]);                    // grey
  EXPECT_EQ(unknown[1], unknown[2]);
}

}  // namespace
}  // namespace pitchlab::mission
