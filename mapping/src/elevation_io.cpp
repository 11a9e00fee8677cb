#include "pitchlab/mapping/elevation_io.hpp"

#include <cerrno>
#include <cstddef>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>
#include <string_view>

#include "pitchlab/mapping/atomic_file.hpp"
#include "pitchlab/mapping/physical_memory.hpp"
#include "pitchlab/sensors/number_text.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::mapping {
namespace {

constexpr char kMagic[8] = {'P', 'L', 'E', 'L', 'E', 'V', '0', '3'};
// Runs of 52-byte records without the second extremes: read, no longer written.
constexpr char kMagicRuns52[8] = {'P', 'L', 'E', 'L', 'E', 'V', '0', '2'};
// Every 52-byte record in order, no runs: read, no longer written.
constexpr char kMagicDense[8] = {'P', 'L', 'E', 'L', 'E', 'V', '0', '1'};
static_assert(sizeof(CellStats) == 60, "the .plem record layout is 15 packed 4-byte fields");
// PLELEV01/02 records: CellStats up to clearance_z.
constexpr std::size_t kRecord52 = 52;
static_assert(offsetof(CellStats, next_min_z) == kRecord52, "the new fields follow the old record");

// A cell nothing reached: no point, no ray (CellStats' defaults, byte for byte: 15 packed fields).
bool Unseen(const CellStats& c) {
  static const CellStats kUnseen{};
  return std::memcmp(&c, &kUnseen, sizeof(CellStats)) == 0;
}

std::uint64_t Fnv1a(std::string_view bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

template <typename T>
void Put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <typename T>
bool Get(const std::string& in, std::size_t& pos, T* v) {
  if (pos + sizeof(T) > in.size()) return false;
  std::memcpy(v, in.data() + pos, sizeof(T));
  pos += sizeof(T);
  return true;
}

double LayerValue(const ElevationLayers& L, std::size_t k, RasterLayer layer) {
  switch (layer) {
    case RasterLayer::kMean:
      return L.mean_z[k];
    case RasterLayer::kMin:
      return L.min_z[k];
    case RasterLayer::kMax:
      return L.max_z[k];
    case RasterLayer::kRoughness:
      return L.roughness[k];
    case RasterLayer::kInclination:
      return L.Tilt(k) * (180.0 / M_PI);
  }
  return std::nan("");
}

}  // namespace

Result<void> SaveElevationMap(const ElevationMap& map, const std::string& path) {
  const GridGeometry& g = map.geometry();
  std::string out;
  out.reserve(128 + g.cell_count() * sizeof(CellStats));
  out.append(kMagic, sizeof(kMagic));
  Put(out, g.x_min_m);
  Put(out, g.y_min_m);
  Put(out, g.cell_m);
  Put(out, static_cast<std::int32_t>(g.size_x));
  Put(out, static_cast<std::int32_t>(g.size_y));
  const GeodeticOrigin geo = map.geodetic_origin().value_or(GeodeticOrigin{});
  Put(out, static_cast<std::uint32_t>(map.geodetic_origin().has_value()));
  Put(out, geo.latitude_deg);
  Put(out, geo.longitude_deg);
  Put(out, geo.height_m);
  Put(out, static_cast<std::uint32_t>(sizeof(CellStats)));
  // Runs of unseen cells, then of seen ones with their records. A run's map covers its world and
  // is mostly unseen (the default terrain run: 81 % of 410 k cells, in 1953 runs): its file was
  // 21 MB of mostly default records, a 350 m DEM world's 655 MB.
  const std::vector<CellStats>& cells = map.cells();
  for (std::size_t k = 0; k < cells.size();) {
    std::size_t seen = k;
    while (seen < cells.size() && Unseen(cells[seen])) ++seen;
    std::size_t end = seen;
    while (end < cells.size() && !Unseen(cells[end])) ++end;
    Put(out, static_cast<std::uint32_t>(seen - k));  // a grid holds at most 2^31 cells
    Put(out, static_cast<std::uint32_t>(end - seen));
    out.append(reinterpret_cast<const char*>(cells.data() + seen),
               (end - seen) * sizeof(CellStats));
    k = end;
  }
  Put(out, Fnv1a(out));
  return WriteFileAtomically(path, out);
}

namespace {

// Why the header's or the cells' values cannot be a map's, or empty when they can: a finite corner
// within sensors::kMaxCoordinate_m, a finite cell, a geodetic origin on the globe, and finite
// statistics in every known cell (an unknown cell keeps its +-inf defaults; clearance is +inf
// where no ray crossed).
std::string InvalidValues(const GridGeometry& g, const GeodeticOrigin* geo,
                          const std::vector<CellStats>& cells) {
  const auto number = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  if (!(std::abs(g.x_min_m) <= sensors::kMaxCoordinate_m &&
        std::abs(g.y_min_m) <= sensors::kMaxCoordinate_m)) {
    return "corner (" + number(g.x_min_m) + ", " + number(g.y_min_m) +
           ") m is not finite or lies beyond 100 km";
  }
  if (!std::isfinite(g.cell_m)) return "cell size " + number(g.cell_m) + " m is not finite";
  if (geo && !(std::abs(geo->latitude_deg) <= 90 && std::abs(geo->longitude_deg) <= 180 &&
               std::isfinite(geo->height_m))) {
    return "geodetic origin (" + number(geo->latitude_deg) + ", " + number(geo->longitude_deg) +
           ", " + number(geo->height_m) + ") is not on the globe";
  }
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const CellStats& c = cells[i];
    if (!c.known()) continue;
    const float values[] = {c.mean_x, c.mean_y, c.mean_z, c.c_xx, c.c_xy, c.c_xz,
                            c.c_yy,   c.c_yz,   c.c_zz,   c.min_z, c.max_z};
    for (float v : values) {
      if (!std::isfinite(v)) {
        return "cell " + std::to_string(i) + " (column " + std::to_string(i % g.size_x) +
               ", row " + std::to_string(i / g.size_x) + ") holds a non-finite value (" +
               number(v) + ")";
      }
    }
    if (std::isnan(c.clearance_z)) return "cell " + std::to_string(i) + " has a NaN clearance";
    // Second extremes within the extremes: +-inf for one point, finite for more.
    if (!(c.min_z <= c.next_min_z && c.next_max_z <= c.max_z) ||
        (c.count > 1 && !(std::isfinite(c.next_min_z) && std::isfinite(c.next_max_z)))) {
      return "cell " + std::to_string(i) + " has second extremes (" + number(c.next_min_z) + ", " +
             number(c.next_max_z) + ") outside its extremes (" + number(c.min_z) + ", " +
             number(c.max_z) + ")";
    }
  }
  return "";
}

// `count` records of `record` bytes at `from` into `to`. A 52-byte record of earlier versions
// holds no second extremes: its extremes stand for them, so the map's steps read as they did.
void CopyRecords(const char* from, std::size_t count, std::size_t record, CellStats* to) {
  if (record == sizeof(CellStats)) {
    std::memcpy(to, from, count * sizeof(CellStats));
    return;
  }
  for (std::size_t k = 0; k < count; ++k) {
    std::memcpy(static_cast<void*>(&to[k]), from + k * record, kRecord52);
    if (to[k].known()) {
      to[k].next_min_z = to[k].min_z;
      to[k].next_max_z = to[k].max_z;
    }
  }
}

// The cell records of `record` bytes after the header at `pos` into `cells` (sized to the grid):
// every record in order (PLELEV01), or runs of unseen and seen cells (PLELEV02/03), none reaching
// past the grid or the file's hash. Why they do not fit, or empty.
std::string ReadCells(const std::string& bytes, std::size_t pos, bool dense, std::size_t record,
                      std::vector<CellStats>& cells) {
  const std::size_t end = bytes.size() - 8;  // the hash
  if (dense) {
    if (pos + cells.size() * record != end) return "size does not match the grid";
    CopyRecords(bytes.data() + pos, cells.size(), record, cells.data());
    return "";
  }
  for (std::size_t k = 0; k < cells.size();) {
    std::uint32_t unseen = 0, seen = 0;
    if (pos + 8 > end || !Get(bytes, pos, &unseen) || !Get(bytes, pos, &seen))
      return "cell runs end before cell " + std::to_string(k) + " of " +
             std::to_string(cells.size());
    if (unseen + std::uint64_t{seen} == 0 || k + unseen + std::uint64_t{seen} > cells.size())
      return "a run of " + std::to_string(unseen) + " + " + std::to_string(seen) +
             " cells at cell " + std::to_string(k) + " does not fit the grid of " +
             std::to_string(cells.size());
    k += unseen;  // left at CellStats' defaults
    if (pos + std::uint64_t{seen} * record > end) return "truncated cell records";
    CopyRecords(bytes.data() + pos, seen, record, cells.data() + k);
    pos += seen * record;
    k += seen;
  }
  return pos == end ? "" : "size does not match the grid";
}

}  // namespace

Result<ElevationMap> LoadElevationMap(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Fail(Error::Code::kNotFound, path + ": cannot open: " + std::strerror(errno));
  // Read once into a buffer of the file's size: a truth map is ~20 MB, and a stream's growing
  // copies cost as much as the rest of the load.
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);  // a folder: an error
  if (ec) return Fail(Error::Code::kInvalidArgument, path + ": cannot read: " + ec.message());
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) {
    return Fail(Error::Code::kFailed, path + ": cannot read all of its " + std::to_string(size) +
                                          " bytes");
  }
  const auto bad = [&](const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, path + ": not a pitchlab elevation map: " + why);
  };
  const auto magic = [&](const char* m) {
    return bytes.size() >= sizeof(kMagic) + 8 && std::memcmp(bytes.data(), m, sizeof(kMagic)) == 0;
  };
  const bool dense = magic(kMagicDense);
  const std::size_t expected_record = magic(kMagic) ? sizeof(CellStats) : kRecord52;
  if (!magic(kMagic) && !magic(kMagicRuns52) && !dense)
    return bad("bad magic (expected PLELEV03, or PLELEV02/01 of earlier versions)");
  std::uint64_t stored_hash = 0;
  std::memcpy(&stored_hash, bytes.data() + bytes.size() - 8, 8);
  if (Fnv1a(std::string_view(bytes).substr(0, bytes.size() - 8)) != stored_hash)
    return bad("hash mismatch (corrupt or truncated)");
  std::size_t pos = sizeof(kMagic);
  GridGeometry g;
  std::int32_t sx = 0, sy = 0;
  std::uint32_t has_geo = 0, record = 0;
  GeodeticOrigin geo;
  if (!Get(bytes, pos, &g.x_min_m) || !Get(bytes, pos, &g.y_min_m) || !Get(bytes, pos, &g.cell_m) ||
      !Get(bytes, pos, &sx) || !Get(bytes, pos, &sy) || !Get(bytes, pos, &has_geo) ||
      !Get(bytes, pos, &geo.latitude_deg) || !Get(bytes, pos, &geo.longitude_deg) ||
      !Get(bytes, pos, &geo.height_m) || !Get(bytes, pos, &record))
    return bad("truncated header");
  if (record != expected_record)
    return bad("cell record of " + std::to_string(record) + " bytes (expected " +
               std::to_string(expected_record) + ")");
  if (sx <= 0 || sy <= 0 || !(g.cell_m > 0)) return bad("empty grid");
  g.size_x = sx;
  g.size_y = sy;
  // Runs describe a grid in a few bytes, so its size is checked before it is allocated: a 100-byte
  // file with a valid hash asked for 17 GB (a mutated header, corrupt_map_test.cpp). At most what
  // GridGeometry makes (2^31 cells) and what this machine's memory holds.
  const double grid_bytes = static_cast<double>(g.cell_count()) * sizeof(CellStats);
  const double memory_bytes = PhysicalMemoryBytes();
  if (g.cell_count() > 2147483647u || grid_bytes > memory_bytes) {
    return bad("a grid of " + std::to_string(sx) + " x " + std::to_string(sy) + " cells (" +
               NumberText(grid_bytes / 1e9) + " GB) is more than a map holds or this machine's " +
               NumberText(memory_bytes / 1e9) + " GB of memory");
  }
  std::vector<CellStats> cells;
  try {
    cells.resize(g.cell_count());
  } catch (const std::bad_alloc&) {
    return Fail(Error::Code::kFailed, path + ": not enough memory for its grid of " +
                                          std::to_string(sx) + " x " + std::to_string(sy) +
                                          " cells (" + NumberText(grid_bytes / 1e9) + " GB)");
  }
  if (const std::string why = ReadCells(bytes, pos, dense, record, cells); !why.empty())
    return bad(why);
  // The hash proves the bytes are as written, not that a writer wrote numbers: a crafted or
  // foreign file with an infinite cell or a NaN height would plan "paths" of NaN coordinates.
  if (const std::string why = InvalidValues(g, has_geo ? &geo : nullptr, cells); !why.empty())
    return bad(why);
  return ElevationMap(g, std::move(cells),
                      has_geo ? std::optional<GeodeticOrigin>(geo) : std::nullopt);
}

std::string ProjectionWkt(const std::optional<GeodeticOrigin>& origin) {
  if (!origin) {
    return "LOCAL_CS[\"pitchlab map frame (x east, y north)\",LOCAL_DATUM[\"pitchlab\",0],"
           "UNIT[\"Meter\",1.0],AXIS[\"X\",EAST],AXIS[\"Y\",NORTH]]";
  }
  char buf[1024];
  std::snprintf(buf, sizeof(buf),
                "PROJCS[\"pitchlab_local_TM\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\","
                "SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],"
                "UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],"
                "PARAMETER[\"False_Easting\",0.0],PARAMETER[\"False_Northing\",0.0],"
                "PARAMETER[\"Central_Meridian\",%.12f],PARAMETER[\"Scale_Factor\",1.0],"
                "PARAMETER[\"Latitude_Of_Origin\",%.12f],UNIT[\"Meter\",1.0]]",
                origin->longitude_deg, origin->latitude_deg);
  return buf;
}

Result<void> WriteEsriAsciiGrid(const ElevationLayers& L,
                                const std::optional<GeodeticOrigin>& origin,
                                const std::string& asc_path, RasterLayer layer) {
  const GridGeometry& g = L.geometry;
  const bool height =
      layer == RasterLayer::kMean || layer == RasterLayer::kMin || layer == RasterLayer::kMax;
  const double z_offset = (origin && height) ? origin->height_m : 0.0;
  std::string out;
  out.reserve(g.cell_count() * 10 + 256);
  char buf[128];
  std::snprintf(buf, sizeof(buf),
                "ncols %d\nnrows %d\nxllcorner %.6f\nyllcorner %.6f\ncellsize %.9g\n"
                "NODATA_value -9999\n",
                g.size_x, g.size_y, g.x_min_m, g.y_min_m, g.cell_m);
  out += buf;
  for (int j = g.size_y - 1; j >= 0; --j) {  // ESRI rows run north to south
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      const double v = L.state[k] == CellState::kObserved ? LayerValue(L, k, layer) : std::nan("");
      if (std::isfinite(v)) {
        std::snprintf(buf, sizeof(buf), i ? " %.4f" : "%.4f", v + z_offset);
      } else {
        std::snprintf(buf, sizeof(buf), i ? " -9999" : "-9999");
      }
      out += buf;
    }
    out += '\n';
  }
  if (auto r = WriteFileAtomically(asc_path, out); !r) return r;
  const std::filesystem::path prj = std::filesystem::path(asc_path).replace_extension(".prj");
  return WriteFileAtomically(prj.string(), ProjectionWkt(origin) + "\n");
}

}  // namespace pitchlab::mapping
