#include "pitchlab/mission/map_figure.hpp"
#include "run_pictures.hpp"

#include <array>
#include <cmath>

#include <gtest/gtest.h>

#include "axis_ticks.hpp"
#include "bitmap_font.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/path_io.hpp"

namespace pitchlab::mission {
namespace {

using Rgb = std::array<int, 3>;

Rgb Pixel(const mapping::RgbImage& img, int x, int y) {
  const std::size_t o = (static_cast<std::size_t>(y) * img.width + x) * 3;
  return {img.rgb[o], img.rgb[o + 1], img.rgb[o + 2]};
}

// A 10 m x 10 m grid of 0.1 m cells at `ppc` px/cell, all grey, with one red cell at (2.05,
// 3.05) m and one blue cell at (8.05, 8.05) m.
mapping::RgbImage GreyMap(const mapping::GridGeometry& g, int ppc) {
  mapping::RgbImage img;
  img.pixels_per_cell = ppc;
  img.width = g.size_x * ppc;
  img.height = g.size_y * ppc;
  img.rgb.assign(static_cast<std::size_t>(img.width) * img.height * 3, 128);
  const auto paint = [&](double x, double y, std::uint8_t r, std::uint8_t gr, std::uint8_t b) {
    const Eigen::Vector2d p = mapping::MapToPixel(g, img, x - 0.05, y + 0.05);  // cell's corner
    for (int dy = 0; dy < ppc; ++dy)
      for (int dx = 0; dx < ppc; ++dx)
        img.Set(static_cast<int>(std::lround(p.x())) + dx,
                static_cast<int>(std::lround(p.y())) + dy, r, gr, b);
  };
  paint(2.05, 3.05, 255, 0, 0);
  paint(8.05, 8.05, 0, 0, 255);
  return img;
}

struct Box {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;  // inclusive
  int count = 0;
  void Add(int x, int y) {
    x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    ++count;
  }
};

Box Find(const mapping::RgbImage& img, const Rgb& c) {
  Box b;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (Pixel(img, x, y) == c) b.Add(x, y);
  return b;
}

class MapFigure : public ::testing::Test {
 protected:
  const mapping::GridGeometry g_ = mapping::GridGeometry::FromArea(0, 0, 10, 10, 0.1);
  static constexpr int kPpc = 4;  // 40 px/m
  const MapWindow window_{{1, 1}, {6, 5}};
};

TEST_F(MapFigure, CropsToTheWindowAtTheMapScale) {
  const mapping::RgbImage fig = ComposeMapFigure(GreyMap(g_, kPpc), g_, window_, {});
  const Box grey = Find(fig, {128, 128, 128});
  // The window is 5 m x 4 m at 40 px/m; the scale bar's white box covers part of its corner.
  EXPECT_EQ(grey.x1 - grey.x0 + 1, 200);
  EXPECT_EQ(grey.y1 - grey.y0 + 1, 160);
  const Box red = Find(fig, {255, 0, 0});
  EXPECT_EQ(red.count, kPpc * kPpc);
  // The red cell's corner (2.0, 3.1) m sits (1.0, 5 - 3.1) m from the window's top left.
  EXPECT_EQ(red.x0 - grey.x0, 40);
  EXPECT_EQ(red.y0 - grey.y0, 76);
  EXPECT_EQ(Find(fig, {0, 0, 255}).count, 0);  // outside the window: cropped away
}

TEST_F(MapFigure, TicksSitAtWholeMetresBelowTheMap) {
  const mapping::RgbImage fig = ComposeMapFigure(GreyMap(g_, kPpc), g_, window_, {});
  const Box grey = Find(fig, {128, 128, 128});
  const int below = grey.y1 + 1 + 3;  // under the frame line, inside the tick marks
  // A 5 m window: a tick every metre, x = 1 m is the window's left edge.
  for (int m = 2; m <= 5; ++m) {
    EXPECT_EQ(Pixel(fig, grey.x0 + 40 * (m - 1), below), (Rgb{0, 0, 0})) << m << " m";
    EXPECT_EQ(Pixel(fig, grey.x0 + 40 * (m - 1) + 20, below), (Rgb{255, 255, 255})) << m;
  }
}

TEST_F(MapFigure, MarksStartAndGoalWhereTheyAre) {
  FigureMarks marks;
  marks.start_m = Eigen::Vector2d(2.0, 4.0);
  const mapping::RgbImage fig = ComposeMapFigure(GreyMap(g_, kPpc), g_, window_, marks);
  const Box grey = Find(fig, {128, 128, 128});
  // The marker's white disc, searched in the map's upper half (the scale bar is in the lower).
  Box white;
  for (int y = grey.y0; y < grey.y0 + 80; ++y)
    for (int x = grey.x0; x <= grey.x1; ++x)
      if (Pixel(fig, x, y) == Rgb{255, 255, 255}) white.Add(x, y);
  ASSERT_GT(white.count, 100);
  const double cx = (white.x0 + white.x1) / 2.0 - grey.x0,
               cy = (white.y0 + white.y1) / 2.0 - grey.y0;
  EXPECT_NEAR(cx, 40 * (2.0 - 1.0), 1.0);
  EXPECT_NEAR(cy, 40 * (5.0 - 4.0), 1.0);
}

TEST_F(MapFigure, ColourBarRunsFromLowAtTheBottomToHighAtTheTop) {
  FigureMarks marks;
  marks.colour_bar = ColourBar{0.0, 2.0, [](double t) {
                                 return std::array<double, 3>{255 * t, 0, 255 * (1 - t)};
                               }};
  const mapping::RgbImage fig = ComposeMapFigure(GreyMap(g_, kPpc), g_, window_, marks);
  Box bar;
  int top_red = -1, bottom_blue = -1;
  for (int y = 0; y < fig.height; ++y) {
    for (int x = 0; x < fig.width; ++x) {
      const Rgb p = Pixel(fig, x, y);
      if (p[1] != 0 || p[0] + p[2] < 250 || p[0] + p[2] > 256 || p == Rgb{255, 0, 0}) continue;
      bar.Add(x, y);
      if (top_red < 0) top_red = p[0];
      bottom_blue = p[2];
    }
  }
  ASSERT_GT(bar.count, 1000);
  EXPECT_GT(bar.x0, Find(fig, {128, 128, 128}).x1);  // right of the map
  EXPECT_GT(top_red, 250);
  EXPECT_GT(bottom_blue, 250);
}

// A stop's picture is made from the part of the map it shows (PictureRegion): pixel for pixel the
// picture the whole map gives, whatever the seen patch's offset against the unknown cells'
// checkerboard, with drops seen only by rays passing below, and a plan that runs off the seen
// ground to a goal far across the map.
TEST(StopPicture, IsThePictureOfTheWholeMap) {
  const mapping::GridGeometry g = mapping::GridGeometry::FromArea(-20, -20, 40, 40, 0.1);
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(3.33, -7.71), Eigen::Vector2d(-6.05, 4.4)}) {
    MissionResult so_far;
    so_far.elevation = mapping::ElevationMap(g);
    std::vector<Eigen::Vector3f> points;
    for (double x = 0; x < 5; x += 0.05) {
      for (double y = 0; y < 4; y += 0.05) {
        // a tilted plane with a 0.3 m wall across it, and a pit 1 m deep from x = 3.5 to 4.2
        // whose floor shows only at its far end: its near part is seen by rays passing below the
        // rim (a drop)
        double z = 0.1 * x + 0.05 * y + (y > 2 && y < 2.3 ? 0.3 : 0.0);
        if (x > 3.5 && x < 4.2) {
          if (x < 4.0) continue;
          z = -1.0;
        }
        points.emplace_back(offset.x() + x, offset.y() + y, z);
      }
    }
    const Eigen::Vector3f sensor(offset.x() - 0.5, offset.y() + 2, 1.0);
    so_far.elevation.InsertScan(points.data(), points.size(), sensor);
    for (int k = 0; k < 3; ++k) {
      TrajectorySample s;
      s.T_world_base_est.translation() = Eigen::Vector3d(offset.x() + 0.5 * k, offset.y() + 1, 0);
      so_far.trajectory.push_back(s);
    }
    planning::Path plan;
    for (const Eigen::Vector2d w : std::array<Eigen::Vector2d, 3>{
             offset + Eigen::Vector2d(1, 1), offset + Eigen::Vector2d(8, 3), {15, 12}}) {
      plan.waypoints.push_back({w.x(), w.y(), 0});
    }
    const mapping::RgbImage picture = StopPicture(ViewOfStop(so_far, plan));

    const mapping::ElevationLayers layers = mapping::ComputeLayers(so_far.elevation);
    std::vector<Eigen::Vector2d> keep = TrajectoryXy(so_far, false);
    for (const planning::Waypoint& w : plan.waypoints) keep.emplace_back(w.x_m, w.y_m);
    const MapWindow window = ExploredWindow(layers, keep);
    mapping::ImageOptions options;
    options.pixels_per_cell = FigurePixelsPerCell(g, window);
    mapping::RgbImage image = mapping::RenderElevationImage(layers, options);
    planning::DrawPath(plan, g, image);
    FigureMarks marks;
    marks.start_m = keep.front();
    marks.goal_m = keep.back();
    marks.colour_bar = HeightBar(layers);
    const mapping::RgbImage whole = ComposeMapFigure(image, g, window, marks);

    ASSERT_EQ(picture.width, whole.width);
    ASSERT_EQ(picture.height, whole.height);
    EXPECT_TRUE(picture.rgb == whole.rgb) << "offset " << offset.transpose();
    EXPECT_GT(Find(whole, {220, 0, 220}).count, 0) << "no drop drawn: the test lost its pit";
  }
}

TEST(Downscale, AveragesWholeBlocks) {
  mapping::RgbImage img;
  img.width = 5;  // the odd column is dropped: 5 / 2 = 2 blocks
  img.height = 2;
  img.rgb = {0,  0, 0, 10, 20, 30, 100, 0, 0, 200, 0, 0, 7, 7, 7,  //
             30, 0, 0, 41, 20, 30, 100, 0, 0, 201, 0, 0, 7, 7, 7};
  const mapping::RgbImage small = Downscale(img, 3);  // factor 2 makes it 2 <= 3 wide
  ASSERT_EQ(small.width, 2);
  ASSERT_EQ(small.height, 1);
  EXPECT_EQ(Pixel(small, 0, 0), (Rgb{20, 10, 15}));  // (0 + 10 + 30 + 41) / 4 = 20.25
  EXPECT_EQ(Pixel(small, 1, 0), (Rgb{150, 0, 0}));   // 150.25
  EXPECT_EQ(Downscale(img, 10).width, 5);            // already small enough
}

TEST(ExploredWindow, IsTheKnownCellsAndThePointsWithAMetreAround) {
  mapping::ElevationLayers layers;
  layers.geometry = mapping::GridGeometry::FromArea(-10, -10, 20, 20, 0.1);
  layers.state.assign(layers.geometry.cell_count(), mapping::CellState::kUnknown);
  layers.state[layers.geometry.Linear(layers.geometry.IndexOf(2.05, 3.05))] =
      mapping::CellState::kObserved;
  const MapWindow w = ExploredWindow(layers, {{-1.0, 0.5}});
  EXPECT_NEAR(w.lo_m.x(), -2.0, 1e-9);
  EXPECT_NEAR(w.lo_m.y(), -0.5, 1e-9);
  EXPECT_NEAR(w.hi_m.x(), 3.1, 1e-9);
  EXPECT_NEAR(w.hi_m.y(), 4.1, 1e-9);
}

TEST(FigurePixelsPerCell, AimsAtTheTargetWidthWithinAMemoryCap) {
  const auto g = mapping::GridGeometry::FromArea(0, 0, 20, 20, 0.1);    // 200 cells a side
  EXPECT_EQ(FigurePixelsPerCell(g, {{0, 0}, {10, 5}}, 1000), 10);       // 100 cells -> 10 px
  EXPECT_EQ(FigurePixelsPerCell(g, {{0, 0}, {0.5, 0.5}}, 1000), 15);    // capped: 3000 / 200
  const auto big = mapping::GridGeometry::FromArea(0, 0, 64, 64, 0.1);  // 640 cells a side
  EXPECT_EQ(FigurePixelsPerCell(big, {{0, 0}, {64, 64}}, 1000), 2);     // 1.6 px rounded
}

TEST(AxisTicks, AreRoundAndLabelledWithoutNoise) {
  EXPECT_DOUBLE_EQ(NiceStep(7.7, 7), 2.0);
  EXPECT_DOUBLE_EQ(NiceStep(30, 7), 5.0);
  EXPECT_NEAR(NiceStep(0.7, 7), 0.1, 1e-12);
  const std::vector<double> t = Ticks(-0.25, 0.41, 0.2);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(TickLabel(t[3], 0.2), "0.4");
  EXPECT_EQ(TickLabel(t[0], 0.2), "-0.2");
  EXPECT_EQ(TickLabel(t[1], 0.2), "0.0");
  EXPECT_EQ(TickLabel(t[2], 0.2), "0.2");
  EXPECT_EQ(TickLabel(-1e-12, 1.0), "0");  // never "-0"
  EXPECT_EQ(TickLabel(-1e-12, 0.5), "0.0");
  EXPECT_EQ(TickLabel(15, 5), "15");
}

TEST(BitmapFont, DrawsTheGlyphsPixelForPixel) {
  mapping::RgbImage img;
  img.width = 20;
  img.height = 10;
  img.rgb.assign(20 * 10 * 3, 255);
  DrawText(img, 0, 0, "-1", 1, 0, 0, 0);
  EXPECT_EQ(TextWidth("-1", 1), 11);
  for (int x = 0; x < 5; ++x) EXPECT_EQ(Pixel(img, x, 3), (Rgb{0, 0, 0})) << x;  // the dash
  EXPECT_EQ(Pixel(img, 0, 2), (Rgb{255, 255, 255}));
  EXPECT_EQ(Pixel(img, 6 + 2, 0), (Rgb{0, 0, 0}));  // the 1's stem, column 2 of the next cell
  EXPECT_EQ(Pixel(img, 6 + 0, 0), (Rgb{255, 255, 255}));
  EXPECT_TRUE(FontHas("z [m] -0.5 S G"));
  EXPECT_FALSE(FontHas("elevation"));
  EXPECT_THROW(DrawText(img, 0, 0, "?", 1, 0, 0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mission
