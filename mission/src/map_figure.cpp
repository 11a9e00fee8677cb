#include "pitchlab/mission/map_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "axis_ticks.hpp"
#include "bitmap_font.hpp"

namespace pitchlab::mission {
namespace {

// 15 x 21 px characters: still ~9 x 12 px where the report shows a 1000 px figure 600 px wide.
constexpr int kFont = 3;
constexpr int kTick_px = 6;
constexpr int kGap_px = 6;
constexpr int kMarkerRadius_px = 17;  // holds one character of kFont (15 x 21) inside its ring
constexpr int kBarWidth_px = 22;
constexpr int kMinBarHeight_px = 240;  // room for at least three labelled ticks
// The whole picture is rendered before cropping: this bounds its memory (3 bytes a pixel).
constexpr int kMaxRenderSide_px = 3000;

using Rgb = std::array<std::uint8_t, 3>;
constexpr Rgb kBlack{0, 0, 0}, kWhite{255, 255, 255};

void Fill(mapping::RgbImage& img, int x0, int y0, int w, int h, const Rgb& c) {
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) img.Set(x, y, c[0], c[1], c[2]);
}

void Outline(mapping::RgbImage& img, int x0, int y0, int w, int h, const Rgb& c) {
  Fill(img, x0 - 1, y0 - 1, w + 2, 1, c);
  Fill(img, x0 - 1, y0 + h, w + 2, 1, c);
  Fill(img, x0 - 1, y0 - 1, 1, h + 2, c);
  Fill(img, x0 + w, y0 - 1, 1, h + 2, c);
}

void Disc(mapping::RgbImage& img, int cx, int cy, int r, const Rgb& c) {
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (dx * dx + dy * dy <= r * r) img.Set(cx + dx, cy + dy, c[0], c[1], c[2]);
}

// A white disc with a black ring and a letter: visible on any map colour.
void Marker(mapping::RgbImage& img, int cx, int cy, const std::string& letter) {
  Disc(img, cx, cy, kMarkerRadius_px, kBlack);
  Disc(img, cx, cy, kMarkerRadius_px - 3, kWhite);
  DrawText(img, cx - TextWidth(letter, kFont) / 2, cy - TextHeight(kFont) / 2, letter, kFont, 0, 0,
           0);
}

// The bar's length: the largest 1, 2 or 5 times a power of ten metres up to a quarter of the
// window's width.
void ScaleBar(mapping::RgbImage& img, int x0, int y_bottom, double width_m, double px_per_m) {
  const double quarter = width_m / 4;
  const double mag = std::pow(10.0, std::floor(std::log10(quarter)));
  double length_m = mag;
  for (double m : {5.0, 2.0}) {
    if (m * mag <= quarter) {
      length_m = m * mag;
      break;
    }
  }
  const int len_px = static_cast<int>(std::lround(length_m * px_per_m));
  const std::string text = TickLabel(length_m, length_m) + " m";
  const int box_w = std::max(len_px, TextWidth(text, kFont)) + 2 * kGap_px;
  const int box_h = TextHeight(kFont) + 3 * kGap_px + 6;
  const int bx = x0 + kGap_px, by = y_bottom - kGap_px - box_h;
  Fill(img, bx, by, box_w, box_h, kWhite);
  Outline(img, bx, by, box_w, box_h, kBlack);
  DrawText(img, bx + kGap_px, by + kGap_px, text, kFont, 0, 0, 0);
  const int bar_y = by + box_h - kGap_px - 4;
  Fill(img, bx + kGap_px, bar_y, len_px, 4, kBlack);
  Fill(img, bx + kGap_px, bar_y - 4, 2, 8, kBlack);
  Fill(img, bx + kGap_px + len_px - 2, bar_y - 4, 2, 8, kBlack);
}

void DrawColourBar(mapping::RgbImage& img, int x0, int y0, int h, const ColourBar& bar) {
  for (int y = 0; y < h; ++y) {
    const std::array<double, 3> c = bar.colour(1.0 - (y + 0.5) / h);  // high at the top
    Fill(img, x0, y0 + y, kBarWidth_px, 1,
         {static_cast<std::uint8_t>(std::clamp(c[0], 0.0, 255.0)),
          static_cast<std::uint8_t>(std::clamp(c[1], 0.0, 255.0)),
          static_cast<std::uint8_t>(std::clamp(c[2], 0.0, 255.0))});
  }
  Outline(img, x0, y0, kBarWidth_px, h, kBlack);
  const double span = bar.hi_m - bar.lo_m;
  const double step = NiceStep(span, std::max(2, h / (4 * TextHeight(kFont))));
  for (double z : Ticks(bar.lo_m, bar.hi_m, step)) {
    const int y = y0 + static_cast<int>(std::lround((bar.hi_m - z) / span * (h - 1)));
    Fill(img, x0 + kBarWidth_px, y, kTick_px, 1, kBlack);
    DrawText(img, x0 + kBarWidth_px + kTick_px + 4, y - TextHeight(kFont) / 2, TickLabel(z, step),
             kFont, 0, 0, 0);
  }
  DrawText(img, x0, y0 - TextHeight(kFont) - 2 * kGap_px, "z [m]", kFont, 0, 0, 0);
}

int ColourBarLabelWidth(const ColourBar& bar, int h) {
  const double step = NiceStep(bar.hi_m - bar.lo_m, std::max(2, h / (4 * TextHeight(kFont))));
  int w = TextWidth("z [m]", kFont);
  for (double z : Ticks(bar.lo_m, bar.hi_m, step))
    w = std::max(w, kTick_px + 4 + TextWidth(TickLabel(z, step), kFont));
  return w;
}

// Where the parts of a figure go [px]: the map area at (left, top), margins around it.
struct Frame {
  double px_per_m = 1, step_m = 1;
  int map_w = 0, map_h = 0, bar_h = 0;
  int left = 0, top = 0, right = 0, bottom = 0;
  int X(double x_m, const MapWindow& w) const {
    return left + static_cast<int>(std::lround((x_m - w.lo_m.x()) * px_per_m));
  }
  int Y(double y_m, const MapWindow& w) const {
    return top + static_cast<int>(std::lround((w.hi_m.y() - y_m) * px_per_m));
  }
};

Frame Layout(const mapping::RgbImage& map, const mapping::GridGeometry& g, const MapWindow& w,
             const FigureMarks& marks) {
  Frame f;
  f.px_per_m = map.pixels_per_cell / g.cell_m;
  f.map_w = static_cast<int>(std::lround((w.hi_m.x() - w.lo_m.x()) * f.px_per_m));
  f.map_h = static_cast<int>(std::lround((w.hi_m.y() - w.lo_m.y()) * f.px_per_m));
  f.step_m = NiceStep((w.hi_m - w.lo_m).maxCoeff(), 7);
  int y_label_w = TextWidth("y [m]", kFont);
  for (double y : Ticks(w.lo_m.y(), w.hi_m.y(), f.step_m))
    y_label_w = std::max(y_label_w, TextWidth(TickLabel(y, f.step_m), kFont));
  f.bar_h = std::max(f.map_h, kMinBarHeight_px);
  f.left = y_label_w + kTick_px + 2 * kGap_px;
  f.top = TextHeight(kFont) + 3 * kGap_px;
  f.bottom = kTick_px + 3 * kGap_px + 2 * TextHeight(kFont) + kGap_px;
  f.right = 3 * kGap_px;
  if (marks.colour_bar) {
    f.right += 4 * kGap_px + kBarWidth_px + ColourBarLabelWidth(*marks.colour_bar, f.bar_h);
  }
  return f;
}

// The window's pixels of `map` into the frame's map area; off the map stays white.
void CopyWindow(const mapping::RgbImage& map, const mapping::GridGeometry& g, const MapWindow& w,
                const Frame& f, mapping::RgbImage& out) {
  const Eigen::Vector2d s0 = mapping::MapToPixel(g, map, w.lo_m.x(), w.hi_m.y());
  const int sx0 = static_cast<int>(std::lround(s0.x())),
            sy0 = static_cast<int>(std::lround(s0.y()));
  for (int y = 0; y < f.map_h; ++y) {
    const int sy = y + sy0;
    if (sy < 0 || sy >= map.height) continue;
    for (int x = 0; x < f.map_w; ++x) {
      const int sx = x + sx0;
      if (sx < 0 || sx >= map.width) continue;
      const std::uint8_t* p = &map.rgb[(static_cast<std::size_t>(sy) * map.width + sx) * 3];
      out.Set(f.left + x, f.top + y, p[0], p[1], p[2]);
    }
  }
}

// The frame, ticks every step_m labelled in metres, and the axis titles.
void DrawAxes(mapping::RgbImage& out, const MapWindow& w, const Frame& f) {
  Outline(out, f.left, f.top, f.map_w, f.map_h, kBlack);
  const int below = f.top + f.map_h;
  for (double x : Ticks(w.lo_m.x(), w.hi_m.x(), f.step_m)) {
    const int px = f.X(x, w);
    Fill(out, px, below, 1, kTick_px, kBlack);
    const std::string s = TickLabel(x, f.step_m);
    DrawText(out, px - TextWidth(s, kFont) / 2, below + kTick_px + kGap_px, s, kFont, 0, 0, 0);
  }
  for (double y : Ticks(w.lo_m.y(), w.hi_m.y(), f.step_m)) {
    const int py = f.Y(y, w);
    Fill(out, f.left - kTick_px, py, kTick_px, 1, kBlack);
    const std::string s = TickLabel(y, f.step_m);
    DrawText(out, f.left - kTick_px - kGap_px - TextWidth(s, kFont), py - TextHeight(kFont) / 2, s,
             kFont, 0, 0, 0);
  }
  const std::string x_title = "x [m]";
  DrawText(out, f.left + f.map_w / 2 - TextWidth(x_title, kFont) / 2,
           below + kTick_px + 3 * kGap_px + TextHeight(kFont), x_title, kFont, 0, 0, 0);
  DrawText(out, kGap_px, kGap_px, "y [m]", kFont, 0, 0, 0);
}

}  // namespace

ColourBar HeightBar(const mapping::ElevationLayers& layers) {
  const auto [lo, hi] = mapping::ElevationRampRange(layers);
  return {lo, hi, mapping::ElevationRamp};
}

MapWindow ExploredWindow(const mapping::ElevationLayers& layers,
                         const std::vector<Eigen::Vector2d>& points_m) {
  const mapping::GridGeometry& g = layers.geometry;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (int j = 0; j < g.size_y; ++j) {
    for (int i = 0; i < g.size_x; ++i) {
      if (layers.state[g.Linear({i, j})] == mapping::CellState::kUnknown) continue;
      const Eigen::Vector2d c = g.CenterOf({i, j});
      lo = lo.cwiseMin(c - Eigen::Vector2d::Constant(g.cell_m / 2));
      hi = hi.cwiseMax(c + Eigen::Vector2d::Constant(g.cell_m / 2));
    }
  }
  for (const Eigen::Vector2d& p : points_m) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!std::isfinite(lo.x())) return {{g.x_min_m, g.y_min_m}, {g.x_max_m(), g.y_max_m()}};
  return {lo - Eigen::Vector2d::Constant(kPictureWindowMargin_m),
          hi + Eigen::Vector2d::Constant(kPictureWindowMargin_m)};
}

int FigurePixelsPerCell(const mapping::GridGeometry& g, const MapWindow& w, int target_px) {
  const double window_cells = (w.hi_m - w.lo_m).maxCoeff() / g.cell_m;
  const int wanted = static_cast<int>(std::lround(target_px / std::max(window_cells, 1.0)));
  const int cap = kMaxRenderSide_px / std::max(1, std::max(g.size_x, g.size_y));
  return std::max(1, std::min(wanted, cap));
}

mapping::RgbImage ComposeMapFigure(const mapping::RgbImage& map, const mapping::GridGeometry& g,
                                   const MapWindow& w, const FigureMarks& marks) {
  const Frame f = Layout(map, g, w, marks);
  mapping::RgbImage out;
  out.pixels_per_cell = map.pixels_per_cell;
  out.width = f.left + f.map_w + f.right;
  out.height = f.top + std::max(f.map_h, marks.colour_bar ? f.bar_h : 0) + f.bottom;
  out.rgb.assign(static_cast<std::size_t>(out.width) * out.height * 3, 255);
  CopyWindow(map, g, w, f, out);
  DrawAxes(out, w, f);
  ScaleBar(out, f.left, f.top + f.map_h, w.hi_m.x() - w.lo_m.x(), f.px_per_m);
  const auto mark = [&](const std::optional<Eigen::Vector2d>& p, const char* letter) {
    if (p) Marker(out, f.X(p->x(), w), f.Y(p->y(), w), letter);
  };
  mark(marks.start_m, "S");
  mark(marks.goal_m, "G");
  if (marks.colour_bar) {
    DrawColourBar(out, f.left + f.map_w + 4 * kGap_px, f.top, f.bar_h, *marks.colour_bar);
  }
  return out;
}

}  // namespace pitchlab::mission
