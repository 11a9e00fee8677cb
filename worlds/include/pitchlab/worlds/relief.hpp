#pragma once

#include <cstdint>
#include <vector>

#include "pitchlab/worlds/height_grid.hpp"
#include "pitchlab/worlds/world_metadata.hpp"

namespace pitchlab::worlds {

/// Fine, robot-scale relief added on top of a smooth surface: rocks, cracks and roughness.
struct ReliefConfig {
  std::uint64_t seed = 1;             ///< same seed, same relief
  double rocks_per_100m2 = 1.0;       ///< rock density [1/(100 m^2)]
  double rock_radius_min_m = 0.15;    ///< [m]
  double rock_radius_max_m = 0.6;     ///< [m]
  double rock_height_min_m = 0.08;    ///< [m]
  double rock_height_max_m = 0.45;    ///< [m]
  double cracks_per_1000m2 = 1.5;     ///< crack density [1/(1000 m^2)]
  double crack_length_min_m = 2.0;    ///< [m]
  double crack_length_max_m = 8.0;    ///< [m]
  double crack_width_m = 0.25;        ///< full width at the top [m]
  double crack_depth_m = 0.3;         ///< [m]
  double roughness_m = 0.015;         ///< amplitude of cell-scale value noise [m]
  double keep_clear_radius_m = 2.5;   ///< no rocks or cracks this close to keep_clear [m]
  std::vector<StartPose> keep_clear;  ///< e.g. the default start and goal (yaw unused)
};

/// Adds rocks (smooth caps), cracks (V-shaped grooves along straight segments) and roughness to
/// `grid`, deterministically from `config.seed`. Throws std::invalid_argument on negative sizes.
void AddFineRelief(const ReliefConfig& config, HeightGrid& grid);

/// A start spot on a 2 m lattice at least `margin_m` inside `grid`: the one nearest the centre
/// whose steepest slope within `radius_m` is below 3 deg, else the one with the smallest such
/// slope. Yaw 0.
StartPose FindFlatStart(const HeightGrid& grid, double radius_m, double margin_m);

}  // namespace pitchlab::worlds
