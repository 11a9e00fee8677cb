#pragma once
// A map picture a person can read on its own: cropped to what the robot saw, framed by axes in
// metres, with a scale bar, start (S) and goal (G) markers and, for heights, a colour bar.

#include <array>
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"

namespace pitchlab::mission {

/// The part of the map a figure shows, in the map frame [m].
struct MapWindow {
  Eigen::Vector2d lo_m{0, 0}, hi_m{0, 0};
};

/// ExploredWindow's margin around what it holds: keeps the start and goal markers (kMarkerRadius_px
/// at ~0.05 m/px) and half a robot width clear of the border [m].
inline constexpr double kPictureWindowMargin_m = 1.0;

/// The bounding box of the cells the map knows (observed or drop), grown to hold `points_m`
/// (start, goal, trajectories) and a margin that keeps the markers and the robot's footprint at
/// the border inside; the whole grid when no cell is known.
MapWindow ExploredWindow(const mapping::ElevationLayers& layers,
                         const std::vector<Eigen::Vector2d>& points_m);

/// Pixels per cell at which `window` of a picture of `grid` is about `target_px` on its longer
/// side [px/cell], at least 1, and small enough that the whole picture stays a few thousand pixels.
int FigurePixelsPerCell(const mapping::GridGeometry& grid, const MapWindow& window,
                        int target_px = 1000);

/// A colour bar: heights [m] at its ends and the colour [0-255] of a relative height in [0, 1].
struct ColourBar {
  double lo_m = 0, hi_m = 1;
  std::function<std::array<double, 3>(double)> colour;
};

/// The elevation colour bar of `layers`: its heights' ramp range and mapping::ElevationRamp.
ColourBar HeightBar(const mapping::ElevationLayers& layers);

/// What a figure marks besides the axes and the scale bar.
struct FigureMarks {
  std::optional<Eigen::Vector2d> start_m, goal_m;  ///< [m]
  std::optional<ColourBar> colour_bar;
};

/// `map` (a picture of `grid`, north up, as mapping::RenderElevationImage draws it) cropped to
/// `window` on a white canvas with axes (ticks labelled in metres), a scale bar in the lower left
/// corner, the marks and the colour bar on the right. Parts of the window off the map are white.
mapping::RgbImage ComposeMapFigure(const mapping::RgbImage& map, const mapping::GridGeometry& grid,
                                   const MapWindow& window, const FigureMarks& marks);

}  // namespace pitchlab::mission
