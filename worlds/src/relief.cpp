#include "pitchlab/worlds/relief.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "random.hpp"

namespace pitchlab::worlds {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Index range of vertices within [lo, hi] along one axis, clamped to the grid.
void IndexRange(double lo, double hi, double origin, double cell, int n, int& i0, int& i1) {
  i0 = std::max(0, static_cast<int>(std::ceil((lo - origin) / cell)));
  i1 = std::min(n - 1, static_cast<int>(std::floor((hi - origin) / cell)));
}

bool NearKeepClear(const ReliefConfig& config, double x, double y, double radius) {
  for (const StartPose& p : config.keep_clear) {
    if (std::hypot(x - p.x_m, y - p.y_m) < config.keep_clear_radius_m + radius) return true;
  }
  return false;
}

// A rock: a smooth cap h * (1 - (r/R)^2)^2 that rises out of the surface; max() keeps rocks from
// digging holes where they overlap cracks or each other.
void AddRock(HeightGrid& grid, double cx, double cy, double radius, double height) {
  int x0, x1, y0, y1;
  IndexRange(cx - radius, cx + radius, grid.x0_m, grid.cell_m, grid.nx, x0, x1);
  IndexRange(cy - radius, cy + radius, grid.y0_m, grid.cell_m, grid.ny, y0, y1);
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const double dx = grid.x0_m + ix * grid.cell_m - cx, dy = grid.y0_m + iy * grid.cell_m - cy;
      const double s = 1.0 - (dx * dx + dy * dy) / (radius * radius);
      if (s > 0.0) grid.At(ix, iy) += height * s * s;
    }
  }
}

// A crack: a V-shaped groove of `width` and `depth` along the segment (ax, ay)-(bx, by).
void AddCrack(HeightGrid& grid, double ax, double ay, double bx, double by, double width,
              double depth) {
  const double half = 0.5 * width;
  int x0, x1, y0, y1;
  IndexRange(std::min(ax, bx) - half, std::max(ax, bx) + half, grid.x0_m, grid.cell_m, grid.nx, x0,
             x1);
  IndexRange(std::min(ay, by) - half, std::max(ay, by) + half, grid.y0_m, grid.cell_m, grid.ny, y0,
             y1);
  const double lx = bx - ax, ly = by - ay, len2 = lx * lx + ly * ly;
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const double px = grid.x0_m + ix * grid.cell_m - ax, py = grid.y0_m + iy * grid.cell_m - ay;
      const double t = std::clamp((px * lx + py * ly) / len2, 0.0, 1.0);
      const double d = std::hypot(px - t * lx, py - t * ly);
      // Tapers to nothing at both ends, like a real crack.
      const double taper = std::sin(kPi * t);
      if (d < half) grid.At(ix, iy) -= depth * taper * (1.0 - d / half);
    }
  }
}

}  // namespace

void AddFineRelief(const ReliefConfig& config, HeightGrid& grid) {
  if (config.rocks_per_100m2 < 0 || config.cracks_per_1000m2 < 0 || config.rock_radius_min_m <= 0 ||
      config.rock_radius_max_m < config.rock_radius_min_m || config.crack_width_m <= 0 ||
      config.crack_length_min_m <= 0 || config.crack_length_max_m < config.crack_length_min_m) {
    throw std::invalid_argument("ReliefConfig: sizes and densities must be positive and ordered");
  }
  SplitMix64 rng(config.seed);
  const double w = grid.XMax_m() - grid.x0_m, h = grid.YMax_m() - grid.y0_m;
  const int rocks = static_cast<int>(std::lround(config.rocks_per_100m2 * w * h / 100.0));
  for (int k = 0; k < rocks; ++k) {
    const double x = rng.Uniform(grid.x0_m, grid.XMax_m()),
                 y = rng.Uniform(grid.y0_m, grid.YMax_m());
    const double radius = rng.Uniform(config.rock_radius_min_m, config.rock_radius_max_m);
    const double height = rng.Uniform(config.rock_height_min_m, config.rock_height_max_m);
    if (!NearKeepClear(config, x, y, radius)) AddRock(grid, x, y, radius, height);
  }
  const int cracks = static_cast<int>(std::lround(config.cracks_per_1000m2 * w * h / 1000.0));
  for (int k = 0; k < cracks; ++k) {
    const double x = rng.Uniform(grid.x0_m, grid.XMax_m()),
                 y = rng.Uniform(grid.y0_m, grid.YMax_m());
    const double length = rng.Uniform(config.crack_length_min_m, config.crack_length_max_m);
    const double heading = rng.Uniform(0.0, 2.0 * kPi);
    const double bx = x + length * std::cos(heading), by = y + length * std::sin(heading);
    if (NearKeepClear(config, x, y, 0.0) || NearKeepClear(config, bx, by, 0.0) ||
        NearKeepClear(config, 0.5 * (x + bx), 0.5 * (y + by), 0.0)) {
      continue;
    }
    AddCrack(grid, x, y, bx, by, config.crack_width_m, config.crack_depth_m);
  }
  if (config.roughness_m > 0.0) {
    // Roughness at ~3 cells; spared near the start so it stays flat.
    const std::uint64_t seed = rng.Next();
    const double frequency = 1.0 / (3.0 * grid.cell_m);
    for (int iy = 0; iy < grid.ny; ++iy) {
      for (int ix = 0; ix < grid.nx; ++ix) {
        const double x = grid.x0_m + ix * grid.cell_m, y = grid.y0_m + iy * grid.cell_m;
        if (NearKeepClear(config, x, y, 0.0)) continue;
        grid.At(ix, iy) += config.roughness_m * ValueNoise(seed, 0, x * frequency, y * frequency);
      }
    }
  }
}

StartPose FindFlatStart(const HeightGrid& grid, double radius_m, double margin_m) {
  // Flat enough for a P3 to stand level and start scanning; below this, nearer the centre wins.
  constexpr double kFlatEnough_rad = 3.0 * kPi / 180.0;
  const double cx = 0.5 * (grid.x0_m + grid.XMax_m()), cy = 0.5 * (grid.y0_m + grid.YMax_m());
  StartPose best{cx, cy, 0.0};
  double best_score = std::numeric_limits<double>::infinity();
  const int step = std::max(1, static_cast<int>(std::lround(2.0 / grid.cell_m)));
  const int reach = static_cast<int>(std::ceil(radius_m / grid.cell_m));
  const int margin = static_cast<int>(std::ceil(margin_m / grid.cell_m));
  for (int iy = margin; iy < grid.ny - margin; iy += step) {
    for (int ix = margin; ix < grid.nx - margin; ix += step) {
      double slope = 0.0;
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          const int jx = std::clamp(ix + dx, 0, grid.nx - 1);
          const int jy = std::clamp(iy + dy, 0, grid.ny - 1);
          slope = std::max(slope, grid.Slope_rad(jx, jy));
        }
      }
      const double x = grid.x0_m + ix * grid.cell_m, y = grid.y0_m + iy * grid.cell_m;
      // Flat-enough spots rank by distance to the centre (score < 1e6 m), the rest by slope.
      const double score = slope <= kFlatEnough_rad ? std::hypot(x - cx, y - cy) : 1e6 + slope;
      if (score < best_score) {
        best = StartPose{x, y, 0.0};
        best_score = score;
      }
    }
  }
  return best;
}

}  // namespace pitchlab::worlds
