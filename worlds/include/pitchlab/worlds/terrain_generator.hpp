#pragma once

#include <cstdint>
#include <filesystem>

#include "pitchlab/worlds/height_grid.hpp"

namespace pitchlab::worlds {

/// The procedural outdoor `terrain` world: fractal hills, a steep butte and a ridge beyond a P3's
/// slope limit, rocks and cracks, level pads at the default start and goal.
struct TerrainConfig {
  std::uint64_t seed = 20120917;    ///< the default world's seed
  double size_m = 64.0;             ///< side of the square terrain [m]
  double cell_m = 0.1;              ///< vertex spacing [m]
  double hill_amplitude_m = 3.0;    ///< amplitude of the lowest noise octave [m]
  double hill_wavelength_m = 22.0;  ///< wavelength of the lowest noise octave [m]
  int octaves = 6;                  ///< fractal noise octaves (each half the amplitude)
  double steep_slope_deg = 38.0;    ///< flank slope of the butte and the ridge [deg]
  double start_pad_radius_m = 3.0;  ///< flat pad around the default start (the origin) [m]
  double goal_x_m = -25.0;          ///< the default goal: 35 m north-west, past the butte [m]
  double goal_y_m = 25.0;           ///< [m]
  double goal_pad_radius_m = 1.5;   ///< flat pad around the default goal [m]
};

/// The terrain heights [m] for `config`, centred on the origin; the same config gives the same
/// heights bit for bit. Throws std::invalid_argument on non-positive sizes.
HeightGrid GenerateTerrainHeights(const TerrainConfig& config);

/// Writes terrain.xml and terrain_hfield.bin into `out_dir` (created if needed); returns the
/// XML's path. Throws std::runtime_error on I/O errors.
std::filesystem::path GenerateTerrainWorld(const TerrainConfig& config,
                                           const std::filesystem::path& out_dir);

}  // namespace pitchlab::worlds
