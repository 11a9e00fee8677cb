#include "pitchlab/mission/traversability_image.hpp"

#include "pitchlab/mission/run_scoring.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace pitchlab::mission {

namespace {

// A black image of `g`'s cells at the options' scale.
mapping::RgbImage BlankImage(const mapping::GridGeometry& g, const mapping::ImageOptions& o) {
  int ppc = o.pixels_per_cell;
  if (ppc <= 0) ppc = std::max(1, o.max_side_px / std::max(1, std::max(g.size_x, g.size_y)));
  mapping::RgbImage img;
  img.pixels_per_cell = ppc;
  img.width = g.size_x * ppc;
  img.height = g.size_y * ppc;
  img.rgb.assign(static_cast<std::size_t>(img.width) * img.height * 3, 0);
  return img;
}

// Paints cell (i, j) of an image of `g`, north up.
void PaintCell(mapping::RgbImage& img, const mapping::GridGeometry& g, int i, int j,
               const std::array<int, 3>& c) {
  const int ppc = img.pixels_per_cell;
  const int y0 = (g.size_y - 1 - j) * ppc, x0 = i * ppc;
  for (int dy = 0; dy < ppc; ++dy)
    for (int dx = 0; dx < ppc; ++dx)
      img.Set(x0 + dx, y0 + dy, static_cast<std::uint8_t>(c[0]), static_cast<std::uint8_t>(c[1]),
              static_cast<std::uint8_t>(c[2]));
}

// The elevation picture's checkerboard for unknown cells.
std::array<int, 3> Checker(int i, int j) {
  return ((i / 4) + (j / 4)) % 2 ? std::array<int, 3>{150, 150, 150}
                                 : std::array<int, 3>{200, 200, 200};
}

}  // namespace

mapping::RgbImage RenderTraversability(const planning::TraversabilityGrid& T,
                                       const mapping::ImageOptions& o) {
  using planning::Blocked;
  const mapping::GridGeometry& g = T.geometry;
  mapping::RgbImage img = BlankImage(g, o);
  // Entering costs span min..max over the free cells; shade by where a cell sits in that span.
  float lo = INFINITY, hi = -INFINITY;
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    if (T.blocked[k] != Blocked::kFree || !std::isfinite(T.z_m[k])) continue;
    lo = std::min(lo, T.enter_cost[k]);
    hi = std::max(hi, T.enter_cost[k]);
  }
  const float span = hi > lo ? hi - lo : 1.0f;
  for (int j = 0; j < g.size_y; ++j) {
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      std::array<int, 3> c{};
      const bool unknown = T.blocked[k] == Blocked::kUnknown ||
                           (T.blocked[k] == Blocked::kFree && !std::isfinite(T.z_m[k]));
      if (unknown) {
        c = Checker(i, j);
      } else {
        switch (T.blocked[k]) {
          case Blocked::kFree: {
            const double t = std::clamp((T.enter_cost[k] - lo) / span, 0.0f, 1.0f);
            c = {static_cast<int>(170 - 120 * t), static_cast<int>(230 - 110 * t),
                 static_cast<int>(150 - 110 * t)};
            break;
          }
          case Blocked::kStep:
            c = {200, 20, 20};
            break;
          case Blocked::kTooSteep:
            c = {245, 140, 0};
            break;
          case Blocked::kDrop:
            c = {220, 0, 220};
            break;
          case Blocked::kNearHazard:
            c = {240, 175, 175};
            break;
          case Blocked::kOccupied:
            c = {30, 30, 30};
            break;
          case Blocked::kUnknown:
            break;
        }
      }
      PaintCell(img, g, i, j, c);
    }
  }
  return img;
}

mapping::RgbImage RenderHazardErrors(const planning::TraversabilityGrid& estimated,
                                     const planning::TraversabilityGrid& truth,
                                     const Eigen::Vector2d& start_m,
                                     const mapping::ImageOptions& o) {
  const mapping::GridGeometry& g = estimated.geometry;
  const std::vector<bool> reachable = planning::ReachableCells(truth, start_m);
  mapping::RgbImage img = BlankImage(g, o);
  for (int j = 0; j < g.size_y; ++j) {
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      std::array<int, 3> c{};
      switch (CompareHazard(estimated, truth, k)) {
        case HazardVerdict::kNotCompared:
          c = Checker(i, j);
          break;
        case HazardVerdict::kAgree:
          c = estimated.Free(k) ? std::array<int, 3>{235, 235, 235}
                                : std::array<int, 3>{120, 120, 120};
          break;
        case HazardVerdict::kFalseHazard:
          c = reachable[k] ? std::array<int, 3>{220, 20, 20} : std::array<int, 3>{245, 160, 205};
          break;
        case HazardVerdict::kMissedHazard:
          c = {20, 60, 230};
          break;
      }
      PaintCell(img, g, i, j, c);
    }
  }
  return img;
}

std::string HazardErrorsLegend() {
  return "Red: a hazard (step, drop, too steep) in the map where the truth is free; pink: the same "
         "where the truth's free cell is out of the robot's reach from its start (a parked car's "
         "roof, cast from above; not counted as a false hazard); blue: a true hazard the map calls "
         "free; light grey: both free; dark grey: both see a hazard or its margin; checkered: not "
         "compared (unknown in either).";
}

std::string TraversabilityLegend() {
  return "Green: free (darker costs more to enter); checkered: unknown; red: step; orange: too "
         "steep; magenta: drop; black: occupied (an occupancy grid's obstacle); pale red: closer "
         "to a hazard than half the robot's width.";
}

}  // namespace pitchlab::mission
