// pitchlab_worldgen: writes the procedural worlds (and worlds from users' DEMs). A thin shell over
// the worlds library (and mapping's DEM reader): parse flags, call one generator, report errors
// once: exit 2 for a mistake on the command line, 1 for one in what it names.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <map>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

#include "dem_input.hpp"
#include "pitchlab/worlds/dem_world.hpp"
#include "pitchlab/worlds/terrain_generator.hpp"

namespace {

constexpr const char* kUsage = R"(usage: pitchlab_worldgen <command> [options]

commands:
  terrain --out DIR [--seed N] [--cell M] [--size M]
      procedural outdoor terrain -> DIR/terrain.xml + DIR/terrain_hfield.bin
  gully --dem FILE.asc --out DIR [--relief-seed N] [--cell M]
      the West Bijou gully (3 m DEM, UTM 13N) -> DIR/gully.xml + DIR/gully_hfield.bin
  dem --in FILE --out DIR/NAME.xml [--utm-zone 13N | --geographic | --local]
      [--area XMIN,YMIN,XMAX,YMAX] [--cell M] [--relief-seed N]
      a DEM -> NAME.xml + NAME_hfield.bin: an ESRI ASCII grid (.asc, with its .prj) or a raster
      GDAL reads (GeoTIFF .tif, SRTM .hgt, .img, .vrt: band 1, heights in metres or feet).
      Placed from the file's coordinate system (longitude/latitude, UTM, local metres) unless
      one of the three options says how to read x, y; without one, local metres. The geodetic
      origin is the valid data's centre (UTM and lon/lat taken on WGS84). --area builds the
      part whose cell centres lie in the rectangle, in the DEM's own coordinates (easting,
      northing or x, y in metres; longitude, latitude in degrees): a DEM tile is kilometres wide

options:
  --cell M   output vertex spacing [m] (terrain 0.1, gully 0.15, dem 0.2)
  --help     this text
)";

// A mistake on the command line (exit 2), not in what it names (exit 1).
struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// "--key value" pairs and "--flag" switches after the command.
std::map<std::string, std::string> ParseFlags(int argc, char** argv) {
  std::map<std::string, std::string> flags;
  for (int i = 2; i < argc; ++i) {
    const std::string key = argv[i];
    if (key.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + key + "'");
    const bool is_switch = key == "--geographic" || key == "--local" || key == "--help";
    if (is_switch) {
      flags[key] = "";
    } else if (i + 1 < argc) {
      flags[key] = argv[++i];
    } else {
      throw UsageError("option " + key + " needs a value");
    }
  }
  return flags;
}

std::string Require(const std::map<std::string, std::string>& flags, const std::string& key) {
  const auto it = flags.find(key);
  if (it == flags.end()) throw UsageError("missing required option " + key);
  return it->second;
}

double NumberFlag(const std::map<std::string, std::string>& flags, const std::string& key,
                  double fallback) {
  const auto it = flags.find(key);
  if (it == flags.end()) return fallback;
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(it->second, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != it->second.size() || !(value > 0.0)) {
    throw UsageError("option " + key + ": expected a positive number, got '" + it->second + "'");
  }
  return value;
}

std::uint64_t SeedFlag(const std::map<std::string, std::string>& flags, const std::string& key,
                       std::uint64_t fallback) {
  const auto it = flags.find(key);
  if (it == flags.end()) return fallback;
  const std::string& text = it->second;
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) {
    throw UsageError("option " + key + ": expected a non-negative integer, got '" + text + "'");
  }
  return std::stoull(text);
}

// "--area XMIN,YMIN,XMAX,YMAX": four numbers, each minimum below its maximum.
pitchlab::worlds::GridArea AreaFlag(const std::string& text) {
  double v[4] = {};
  std::size_t at = 0;
  for (int k = 0; k < 4; ++k) {
    const std::size_t end = k < 3 ? text.find(',', at) : text.size();
    const std::string part = end == std::string::npos ? "" : text.substr(at, end - at);
    char* stop = nullptr;
    v[k] = std::strtod(part.c_str(), &stop);
    if (part.empty() || *stop != '\0' || !std::isfinite(v[k])) {
      throw UsageError("option --area: expected XMIN,YMIN,XMAX,YMAX (four numbers), got '" + text +
                       "'");
    }
    at = end + 1;
  }
  if (!(v[0] < v[2] && v[1] < v[3])) {
    throw UsageError("option --area: XMIN,YMIN,XMAX,YMAX needs XMIN < XMAX and YMIN < YMAX, got '" +
                     text + "'");
  }
  return {v[0], v[1], v[2], v[3]};
}

void CheckKnown(const std::map<std::string, std::string>& flags,
                std::initializer_list<const char*> known) {
  for (const auto& [key, value] : flags) {
    bool found = false;
    for (const char* k : known) found = found || key == k;
    if (!found) throw UsageError("unknown option " + key);
  }
}

int Run(int argc, char** argv) {
  using namespace pitchlab::worlds;
  const std::string command = argc > 1 ? argv[1] : "";
  if (command.empty() || command == "--help" || command == "-h" || command == "help") {
    std::cout << kUsage;
    return command.empty() ? 2 : 0;
  }
  const auto flags = ParseFlags(argc, argv);
  if (flags.count("--help")) {
    std::cout << kUsage;
    return 0;
  }
  if (command == "terrain") {
    CheckKnown(flags, {"--out", "--seed", "--cell", "--size"});
    TerrainConfig config;
    config.seed = SeedFlag(flags, "--seed", config.seed);
    config.cell_m = NumberFlag(flags, "--cell", config.cell_m);
    config.size_m = NumberFlag(flags, "--size", config.size_m);
    std::cout << GenerateTerrainWorld(config, Require(flags, "--out")).string() << "\n";
  } else if (command == "gully") {
    CheckKnown(flags, {"--dem", "--out", "--relief-seed", "--cell"});
    GullyConfig config;
    config.dem_path = Require(flags, "--dem");
    config.relief_seed = SeedFlag(flags, "--relief-seed", config.relief_seed);
    config.cell_m = NumberFlag(flags, "--cell", config.cell_m);
    std::cout << GenerateGullyWorld(config, Require(flags, "--out")).string() << "\n";
  } else if (command == "dem") {
    CheckKnown(flags, {"--in", "--out", "--utm-zone", "--geographic", "--local", "--cell",
                       "--relief-seed", "--area"});
    DemWorldConfig config;
    config.dem_path = Require(flags, "--in");
    const bool placement_given =
        flags.count("--utm-zone") + flags.count("--geographic") + flags.count("--local") > 0;
    config.cell_m = NumberFlag(flags, "--cell", config.cell_m);
    if (flags.count("--relief-seed")) config.relief_seed = SeedFlag(flags, "--relief-seed", 0);
    if (flags.count("--area")) config.area = AreaFlag(flags.at("--area"));
    if (flags.count("--utm-zone") + flags.count("--geographic") + flags.count("--local") > 1) {
      throw UsageError("give at most one of --utm-zone, --geographic, --local");
    }
    if (flags.count("--utm-zone")) {
      try {
        config.placement = ParseUtmZone(flags.at("--utm-zone"));
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
    }
    if (flags.count("--geographic")) config.placement = DemPlacement{DemCoordinates::kGeographic};
    if (flags.count("--local")) config.placement = DemPlacement{DemCoordinates::kLocal};
    // Checked before the DEM is read: a large GeoTIFF takes a while.
    const std::string out = Require(flags, "--out");
    if (std::filesystem::path(out).extension() != ".xml") {
      throw UsageError("--out must name an .xml file, got '" + out + "'");
    }
    pitchlab::worldgen::DemInput input =
        pitchlab::worldgen::ReadDemInput(config.dem_path, placement_given);
    if (!placement_given) config.placement = input.placement;
    config.grid = std::move(input.grid);
    try {
      GenerateDemWorld(config, out);
    } catch (const std::invalid_argument& e) {
      // A DEM tile is kilometres wide: too many vertices at the cell asked for.
      const std::string what = e.what();
      if (config.area || what.find("needs a cell of at least") == std::string::npos) throw;
      throw std::invalid_argument(what + " (or build a part of it: --area)");
    }
    std::cout << out << "\n";
  } else {
    throw UsageError("unknown command '" + command + "'");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << "pitchlab_worldgen: " << e.what() << " (see pitchlab_worldgen --help)\n";
    return 2;
  } catch (const std::bad_alloc&) {  // a DEM header's size, or a cell too fine for the DEM
    std::cerr << "pitchlab_worldgen: out of memory: the DEM (a size in its header) or --cell "
                 "asks for more than this machine has\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pitchlab_worldgen: " << e.what() << "\n";
    return 1;
  }
}
