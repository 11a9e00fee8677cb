#include "plan_input.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "cli_args.hpp"
#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"

namespace pitchlab::apps {
namespace {

template <typename T>
T OrThrow(Result<T> r) {
  if (!r) throw std::runtime_error(r.error().message);
  return std::move(*r);
}

const char* CrsKind(mapping::DemCrs::Kind k) {
  switch (k) {
    case mapping::DemCrs::Kind::kLocal:
      return "local metres";
    case mapping::DemCrs::Kind::kGeographic:
      return "longitude/latitude [deg]";
    case mapping::DemCrs::Kind::kTransverseMercator:
      return "Transverse Mercator [m]";
  }
  return "?";
}

PlanInput FromElevationMap(const mapping::ElevationMap& map, const planning::PlannerConfig& c) {
  PlanInput in;
  in.layers = mapping::ComputeLayers(map);
  in.grid = planning::BuildTraversability(*in.layers, c);
  in.origin = map.geodetic_origin();
  return in;
}

// The raster formats a DEM commonly comes in, read through GDAL: GeoTIFF (SRTM, Copernicus,
// USGS 3DEP, most national DEMs), SRTM's raw .hgt, ERDAS .img, GDAL's own .vrt.
bool IsRasterDem(const std::string& ext) {
  return ext == ".tif" || ext == ".tiff" || ext == ".hgt" || ext == ".img" || ext == ".vrt";
}

// `esri`: an .asc read by our own reader, else a raster read by GDAL (LoadDem decides alike).
PlanInput FromDem(const std::string& path, bool esri, const planning::PlannerConfig& c) {
  auto dem = std::make_shared<mapping::Dem>(OrThrow(mapping::LoadDem(path)));
  PlanInput in = FromElevationMap(dem->map, c);
  in.about = {{"kind", esri ? "DEM (ESRI ASCII grid)" : "DEM (raster, read by GDAL)"},
              {"crs", dem->crs.name},
              {"coordinates", CrsKind(dem->crs.kind)},
              {"file_cell", dem->grid.cell_size},
              {"file_cell_y", dem->grid.cell_size_y},
              {"nodata_cells", dem->nodata_cells},
              {"resampled", dem->resampled}};
  if (dem->resampled) {
    in.about["map_frame"] =
        "east-north-up metres at the grid's centre (the geodetic origin), "
        "resampled bilinearly; --start/--goal in the file's coordinates";
    in.to_map = [dem](const Eigen::Vector2d& p) { return dem->FileToMap(p); };
  } else {
    in.about["map_frame"] = "the file's own x, y [m], every cell as written";
  }
  return in;
}

PlanInput FromOccupancyGrid(const std::string& path, const planning::PlannerConfig& c) {
  const planning::OccupancyGrid occupancy = OrThrow(planning::LoadOccupancyGrid(path));
  PlanInput in;
  in.grid = planning::BuildTraversability(occupancy, c);
  in.about = {{"kind", "map_server occupancy grid"},
              {"map_frame", "the YAML's frame [m] (origin: the lower-left pixel's corner)"},
              {"full_scale_cost", planning::FullScaleCost(c)}};
  return in;
}

}  // namespace

PlanInput LoadPlanInput(const std::string& path, const planning::PlannerConfig& config) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  PlanInput in;
  if (ext == ".plem") {
    in = FromElevationMap(OrThrow(mapping::LoadElevationMap(path)), config);
    in.about = {{"kind", "pitchlab elevation map"}, {"map_frame", "the map's own [m]"}};
  } else if (ext == ".asc" || IsRasterDem(ext)) {
    in = FromDem(path, ext == ".asc", config);
  } else if (ext == ".yaml" || ext == ".yml") {
    in = FromOccupancyGrid(path, config);
  } else {
    throw CliError("MAP '" + path +
                   "' must be a .plem (pitchlab map), an .asc (ESRI ASCII grid, with its .prj), "
                   "a raster DEM (.tif, .tiff, .hgt, .img, .vrt) or a .yaml (map_server "
                   "occupancy grid)");
  }
  in.about["file"] = path;
  in.about["cell_m"] = in.grid.geometry.cell_m;
  in.about["size"] = {in.grid.geometry.size_x, in.grid.geometry.size_y};
  return in;
}

}  // namespace pitchlab::apps
