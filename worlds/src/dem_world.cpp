#include "pitchlab/worlds/dem_world.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "number_format.hpp"
#include "pitchlab/worlds/heightfield_world.hpp"
#include "pitchlab/worlds/relief.hpp"

namespace pitchlab::worlds {
namespace {

// Without a .prj we cannot know the units; a tiny cell inside lon/lat range is almost surely
// degrees, and treating it as metres would silently build a 20 cm world.
DemPlacement ChoosePlacement(const DemWorldConfig& config, const EsriGrid& dem) {
  if (config.placement) return *config.placement;
  if (HasGeographicPrj(config.dem_path)) return DemPlacement{DemCoordinates::kGeographic, 0, true};
  const bool looks_geographic =
      dem.cell_size < 0.01 && std::abs(dem.xll_corner) <= 180.0 && std::abs(dem.yll_corner) <= 90.0;
  if (looks_geographic) {
    throw std::invalid_argument(config.dem_path.string() + ": cellsize " +
                                FormatFixed(dem.cell_size, 9) +
                                " looks like degrees but no .prj says so; give the coordinates "
                                "explicitly (--geographic, --utm-zone ZONE or --local)");
  }
  return DemPlacement{DemCoordinates::kLocal, 0, true};
}

std::string Describe(const DemPlacement& placement) {
  switch (placement.coordinates) {
    case DemCoordinates::kUtm:
      return "UTM " + std::to_string(placement.utm_zone) +
             (placement.northern_hemisphere ? "N" : "S");
    case DemCoordinates::kGeographic:
      return "WGS84 lon/lat";
    case DemCoordinates::kLocal:
      break;
  }
  return "local metric";
}

}  // namespace

DemWorld BuildDemWorld(const DemWorldConfig& config) {
  EsriGrid read;  // a DEM of a few hundred MB is not copied
  if (!config.grid) read = LoadEsriGrid(config.dem_path);
  if (config.area) {
    try {
      read = CropToArea(config.grid ? *config.grid : read, *config.area);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(config.dem_path.string() + ": " + e.what());
    }
  }
  const EsriGrid& dem = config.grid && !config.area ? *config.grid : read;
  const DemPlacement placement = ChoosePlacement(config, dem);
  ProjectedDem projected = [&] {
    try {
      return ProjectDem(dem, placement, config.cell_m);
    } catch (const std::exception& e) {
      throw std::invalid_argument(config.dem_path.string() + ": " + e.what());
    }
  }();
  DemWorld world{std::move(projected.grid), {}, placement, {}};
  WorldMetadata& metadata = world.metadata;
  metadata.default_start = FindFlatStart(world.grid, 1.0, 2.0);
  if (config.relief_seed) {
    ReliefConfig relief;
    relief.seed = *config.relief_seed;
    relief.keep_clear = {metadata.default_start};
    AddFineRelief(relief, world.grid);
  }
  const std::string file = config.dem_path.filename().string();
  metadata.description = config.description.empty()
                             ? "DEM " + file + " (" + Describe(placement) + ") resampled to " +
                                   FormatFixed(config.cell_m, 3) + " m"
                             : config.description;
  metadata.geodetic_origin = projected.geodetic_origin;
  const HeightGrid& grid = world.grid;
  const double margin_m = std::min(1.0, 0.1 * (grid.XMax_m() - grid.x0_m));
  metadata.bounds = Bounds2d{grid.x0_m + margin_m, grid.y0_m + margin_m, grid.XMax_m() - margin_m,
                             grid.YMax_m() - margin_m};
  if (const std::optional<GoalPoint>& goal = config.default_goal; goal) {
    const Bounds2d& b = metadata.bounds;
    if (!(goal->x_m >= b.x_min_m && goal->x_m <= b.x_max_m && goal->y_m >= b.y_min_m &&
          goal->y_m <= b.y_max_m)) {
      throw std::invalid_argument(
          config.dem_path.string() + ": default goal (" + FormatFixed(goal->x_m, 3) + ", " +
          FormatFixed(goal->y_m, 3) + ") lies outside the world's bounds x " +
          FormatFixed(b.x_min_m, 3) + " .. " + FormatFixed(b.x_max_m, 3) + ", y " +
          FormatFixed(b.y_min_m, 3) + " .. " + FormatFixed(b.y_max_m, 3) + " m");
    }
    metadata.default_goal = goal;
  }
  world.comment = "dem: " + file + ", " + Describe(placement) + ", cell " +
                  FormatFixed(config.cell_m, 3) + " m, origin height " +
                  FormatFixed(projected.origin_height_m, 3) + " m";
  if (config.relief_seed) world.comment += ", relief seed " + std::to_string(*config.relief_seed);
  return world;
}

DemPlacement GenerateDemWorld(const DemWorldConfig& config, const std::filesystem::path& out_xml) {
  const DemWorld world = BuildDemWorld(config);
  if (!out_xml.parent_path().empty()) std::filesystem::create_directories(out_xml.parent_path());
  WriteHeightfieldWorld(world.grid, world.metadata, world.comment, out_xml);
  return world.placement;
}

DemWorldConfig GullyDemConfig(const GullyConfig& config) {
  DemWorldConfig dem;
  dem.dem_path = config.dem_path;
  dem.placement = DemPlacement{DemCoordinates::kUtm, 13, true};
  dem.cell_m = config.cell_m;
  dem.relief_seed = config.relief_seed;
  dem.description = "West Bijou Creek gully, CO: 3 m DEM (UTM 13N) upsampled to " +
                    FormatFixed(config.cell_m, 2) + " m with seeded rocks and cracks";
  dem.default_goal = config.default_goal;
  return dem;
}

std::filesystem::path GenerateGullyWorld(const GullyConfig& config,
                                         const std::filesystem::path& out_dir) {
  std::filesystem::create_directories(out_dir);
  const std::filesystem::path xml = out_dir / "gully.xml";
  GenerateDemWorld(GullyDemConfig(config), xml);
  return xml;
}

}  // namespace pitchlab::worlds
