#include "pitchlab/worlds/terrain_generator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "number_format.hpp"
#include "pitchlab/worlds/heightfield_world.hpp"
#include "pitchlab/worlds/relief.hpp"
#include "random.hpp"

namespace pitchlab::worlds {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStartRim_m = 8.0;  // blends of the start and goal pads into the hills [m]
constexpr double kGoalRim_m = 3.0;

void Validate(const TerrainConfig& c) {
  if (!(c.size_m > 0) || !(c.cell_m > 0) || c.size_m / c.cell_m > 8192 || c.octaves < 1 ||
      !(c.hill_wavelength_m > 0) || !(c.steep_slope_deg > 0 && c.steep_slope_deg < 89) ||
      !(c.start_pad_radius_m > 0) || !(c.goal_pad_radius_m > 0) ||
      !(std::max(std::abs(c.goal_x_m), std::abs(c.goal_y_m)) + c.goal_pad_radius_m <
        0.5 * c.size_m)) {
    throw std::invalid_argument("TerrainConfig: size_m " + std::to_string(c.size_m) + ", cell_m " +
                                std::to_string(c.cell_m) +
                                " must be positive with size/cell <= 8192, octaves >= 1, "
                                "steep_slope_deg in (0, 89), positive pad radii and the goal's "
                                "pad inside the terrain");
  }
}

// Hills: fractal value noise; every octave adds about the same slope, so six octaves give
// walkable swells with patches steeper than a P3 can climb.
void AddHills(const TerrainConfig& c, HeightGrid& grid) {
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const double x = grid.x0_m + ix * grid.cell_m, y = grid.y0_m + iy * grid.cell_m;
      grid.At(ix, iy) = c.hill_amplitude_m * FractalNoise(c.seed, x / c.hill_wavelength_m,
                                                          y / c.hill_wavelength_m, c.octaves);
    }
  }
}

// Adds `profile(d)` for every vertex, d = the distance to the segment (ax, ay)-(bx, by).
template <typename Profile>
void AddAlongSegment(HeightGrid& grid, double ax, double ay, double bx, double by,
                     Profile profile) {
  const double lx = bx - ax, ly = by - ay, len2 = std::max(lx * lx + ly * ly, 1e-12);
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const double px = grid.x0_m + ix * grid.cell_m - ax, py = grid.y0_m + iy * grid.cell_m - ay;
      const double t = std::clamp((px * lx + py * ly) / len2, 0.0, 1.0);
      grid.At(ix, iy) += profile(std::hypot(px - t * lx, py - t * ly));
    }
  }
}

// A flat-topped butte and a sharp ridge whose flanks are steeper than a P3's slip limit, placed
// from the seed but at least 12 m from the start pad at the origin.
void AddSteepFeatures(const TerrainConfig& c, SplitMix64& rng, HeightGrid& grid) {
  const double tan_slope = std::tan(c.steep_slope_deg * kPi / 180.0);
  const double reach = 0.5 * c.size_m - 8.0;
  const double butte_heading = rng.Uniform(0.0, 2.0 * kPi);
  const double butte_distance = rng.Uniform(12.0, std::max(12.0, reach));
  const double butte_height_m = rng.Uniform(2.0, 3.0), top_radius_m = rng.Uniform(2.5, 4.0);
  AddAlongSegment(
      grid, butte_distance * std::cos(butte_heading), butte_distance * std::sin(butte_heading),
      butte_distance * std::cos(butte_heading), butte_distance * std::sin(butte_heading),
      [=](double d) {
        return std::clamp(butte_height_m - (d - top_radius_m) * tan_slope, 0.0, butte_height_m);
      });
  // The ridge runs across the terrain on the side opposite the butte.
  const double ridge_heading = butte_heading + kPi + rng.Uniform(-0.5, 0.5);
  const double cx = 16.0 * std::cos(ridge_heading), cy = 16.0 * std::sin(ridge_heading);
  const double along = ridge_heading + 0.5 * kPi, half_length_m = rng.Uniform(7.0, 11.0);
  const double ridge_height_m = rng.Uniform(1.2, 1.8);
  AddAlongSegment(grid, cx - half_length_m * std::cos(along), cy - half_length_m * std::sin(along),
                  cx + half_length_m * std::cos(along), cy + half_length_m * std::sin(along),
                  [=](double d) { return std::max(0.0, ridge_height_m - d * tan_slope); });
}

// Levels a pad of `pad_m` around (cx, cy) and blends it into the surface over a rim of `rim_m`
// (smoothstep). The pad takes the mean height of the surface on the rim's outer circle, so it sits
// at the level of its surroundings: a pad at the height of its centre made a mesa wherever the
// centre was a hilltop, its rim as steep as 30 deg.
void FlattenPad(HeightGrid& grid, double cx, double cy, double pad_m, double rim_m) {
  constexpr int kRingSamples = 64;
  double sum = 0.0;
  for (int k = 0; k < kRingSamples; ++k) {
    const double a = 2.0 * kPi * k / kRingSamples;
    sum +=
        grid.HeightBilinear(cx + (pad_m + rim_m) * std::cos(a), cy + (pad_m + rim_m) * std::sin(a));
  }
  const double pad_height = sum / kRingSamples;
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const double r =
          std::hypot(grid.x0_m + ix * grid.cell_m - cx, grid.y0_m + iy * grid.cell_m - cy);
      const double t = std::clamp((r - pad_m) / rim_m, 0.0, 1.0);
      const double keep = t * t * (3.0 - 2.0 * t);
      grid.At(ix, iy) = pad_height + keep * (grid.At(ix, iy) - pad_height);
    }
  }
}

}  // namespace

HeightGrid GenerateTerrainHeights(const TerrainConfig& config) {
  Validate(config);
  const int n = static_cast<int>(std::lround(config.size_m / config.cell_m)) + 1;
  const double half = 0.5 * (n - 1) * config.cell_m;
  HeightGrid grid(n, n, config.cell_m, -half, -half);
  SplitMix64 rng(config.seed);
  AddHills(config, grid);
  AddSteepFeatures(config, rng, grid);
  FlattenPad(grid, 0.0, 0.0, config.start_pad_radius_m, kStartRim_m);
  FlattenPad(grid, config.goal_x_m, config.goal_y_m, config.goal_pad_radius_m, kGoalRim_m);
  ReliefConfig relief;
  relief.seed = rng.Next();
  relief.rocks_per_100m2 = 1.5;
  relief.cracks_per_1000m2 = 2.0;
  relief.keep_clear = {StartPose{0.0, 0.0, 0.0}, StartPose{config.goal_x_m, config.goal_y_m, 0.0}};
  relief.keep_clear_radius_m = config.start_pad_radius_m;
  AddFineRelief(relief, grid);
  return grid;
}

std::filesystem::path GenerateTerrainWorld(const TerrainConfig& config,
                                           const std::filesystem::path& out_dir) {
  const HeightGrid grid = GenerateTerrainHeights(config);
  WorldMetadata metadata;
  metadata.description =
      "Procedural outdoor terrain: fractal hills, a butte and a ridge steeper "
      "than 30 deg, rocks and cracks; flat pad at the origin";
  const double margin_m = 1.0;
  metadata.bounds = Bounds2d{grid.x0_m + margin_m, grid.y0_m + margin_m, grid.XMax_m() - margin_m,
                             grid.YMax_m() - margin_m};
  metadata.default_start = StartPose{0.0, 0.0, 0.0};
  // Illustrative placement in the hills south of Cluj-Napoca, where the paper's authors worked,
  // so maps and paths open in GIS tools in a plausible place.
  metadata.geodetic_origin = GeodeticPoint{46.72000, 23.60000, 700.0};
  // The default run: 35 m north-west, past the butte and over rougher ground.
  metadata.default_goal = GoalPoint{config.goal_x_m, config.goal_y_m};
  std::filesystem::create_directories(out_dir);
  const std::filesystem::path xml = out_dir / "terrain.xml";
  WriteHeightfieldWorld(grid, metadata,
                        "terrain: seed " + std::to_string(config.seed) + ", size " +
                            FormatFixed(config.size_m, 3) + " m, cell " +
                            FormatFixed(config.cell_m, 3) + " m",
                        xml);
  return xml;
}

}  // namespace pitchlab::worlds
