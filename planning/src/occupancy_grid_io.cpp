// map_server occupancy grids as files (occupancy_grid.hpp): the YAML and its PGM, read strictly
// (every error names the file and the line) and written in raw mode.

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "pitchlab/mapping/atomic_file.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"

namespace pitchlab::planning {
namespace {

namespace fs = std::filesystem;

enum class Mode { kTrinary, kScale, kRaw };

// What the YAML says, with the line of each key for messages.
struct MapYaml {
  std::string image;
  double resolution = 0;
  double origin[3] = {0, 0, 0};
  bool negate = false;
  double occupied_thresh = 0, free_thresh = 0;
  Mode mode = Mode::kTrinary;
};

tl::unexpected<Error> Bad(const std::string& file, int line, const std::string& why) {
  return Fail(Error::Code::kInvalidArgument, file + ":" + std::to_string(line) + ": " + why);
}

int LineOf(const YAML::Node& n) { return n.Mark().line + 1; }  // yaml-cpp counts from 0

Result<std::string> ReadFile(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return Fail(Error::Code::kNotFound,
                path + ": cannot open the " + what + ": " + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// One scalar key's value as T, or an error naming the line.
template <typename T>
Result<T> Scalar(const YAML::Node& value, const std::string& key, const std::string& file) {
  try {
    if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "");
    return value.as<T>();
  } catch (const YAML::Exception&) {
    return Bad(file, LineOf(value),
               "'" + key + "' has an invalid value '" + YAML::Dump(value) + "'");
  }
}

// The keys one by one: every key known, none twice, the required ones present.
Result<MapYaml> ParseMapYaml(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return Bad(file, e.mark.line + 1, "not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) return Bad(file, 1, "expected a map_server YAML (image, resolution, ...)");
  MapYaml y;
  std::map<std::string, int> seen;
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    const int line = LineOf(kv.first);
    if (seen.count(key))
      return Bad(file, line,
                 "'" + key + "' is given twice (lines " + std::to_string(seen[key]) + " and " +
                     std::to_string(line) + ")");
    seen[key] = line;
    if (key == "image") {
      auto s = Scalar<std::string>(v, key, file);
      if (!s) return tl::make_unexpected(s.error());
      y.image = *s;
    } else if (key == "resolution" || key == "occupied_thresh" || key == "free_thresh") {
      auto d = Scalar<double>(v, key, file);
      if (!d) return tl::make_unexpected(d.error());
      (key == "resolution"        ? y.resolution
       : key == "occupied_thresh" ? y.occupied_thresh
                                  : y.free_thresh) = *d;
    } else if (key == "negate") {
      auto n = Scalar<std::string>(v, key, file);
      if (!n) return tl::make_unexpected(n.error());
      if (*n != "0" && *n != "1" && *n != "true" && *n != "false")
        return Bad(file, line, "'negate' must be 0 or 1, not '" + *n + "'");
      y.negate = *n == "1" || *n == "true";
    } else if (key == "mode") {
      auto m = Scalar<std::string>(v, key, file);
      if (!m) return tl::make_unexpected(m.error());
      if (*m != "trinary" && *m != "scale" && *m != "raw")
        return Bad(file, line, "'mode' must be trinary, scale or raw, not '" + *m + "'");
      y.mode = *m == "trinary" ? Mode::kTrinary : *m == "scale" ? Mode::kScale : Mode::kRaw;
    } else if (key == "origin") {
      if (!v.IsSequence() || v.size() != 3) return Bad(file, line, "'origin' must be [x, y, yaw]");
      for (int i = 0; i < 3; ++i) {
        auto d = Scalar<double>(v[i], key, file);
        if (!d) return tl::make_unexpected(d.error());
        if (!std::isfinite(*d)) return Bad(file, line, "'origin' must be finite");
        y.origin[i] = *d;
      }
      if (y.origin[2] != 0)
        return Bad(file, line,
                   "origin yaw " + std::to_string(y.origin[2]) +
                       " rad: a rotated grid is not supported (pitchlab's maps are "
                       "axis-aligned); rotate the image instead");
    } else {
      return Bad(file, line,
                 "unknown key '" + key +
                     "' (a map_server YAML has image, "
                     "resolution, origin, negate, occupied_thresh, free_thresh, mode)");
    }
  }
  for (const char* key :
       {"image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"})
    if (!seen.count(key)) return Bad(file, 1, std::string("missing key '") + key + "'");
  if (!(y.resolution > 0 && std::isfinite(y.resolution)))
    return Bad(file, seen["resolution"], "'resolution' must be a positive number of metres");
  if (!(0 <= y.free_thresh && y.free_thresh < y.occupied_thresh && y.occupied_thresh <= 1))
    return Bad(file, seen["free_thresh"],
               "thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1");
  return y;
}

// A PGM (P5 binary or P2 text): size, maxval and the pixels, row 0 at the top.
struct Pgm {
  int width = 0, height = 0, maxval = 0;
  std::vector<int> pixels;
};

Result<Pgm> ParsePgm(const std::string& bytes, const std::string& file) {
  std::size_t pos = 0;
  int line = 1, token_line = 1;  // where the reader is; where the last token stood
  // The next header token, skipping whitespace and # comments.
  const auto token = [&]() {
    for (;;) {
      while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos])))
        line += bytes[pos++] == '\n';
      if (pos < bytes.size() && bytes[pos] == '#') {
        while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
        continue;
      }
      break;
    }
    const std::size_t start = pos;
    while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    if (pos > start) token_line = line;
    return bytes.substr(start, pos - start);
  };
  const std::string magic = token();
  if (magic != "P5" && magic != "P2")
    return Bad(file, line,
               "not a PGM image (magic '" + magic.substr(0, 8) +
                   "', expected P5 or P2); convert it, e.g. `convert map.png map.pgm`");
  Pgm p;
  int* fields[3] = {&p.width, &p.height, &p.maxval};
  const char* names[3] = {"width", "height", "maxval"};
  for (int f = 0; f < 3; ++f) {
    const std::string t = token();
    char* end = nullptr;
    const long v = std::strtol(t.c_str(), &end, 10);
    const long limit = f == 2 ? 65535 : 1'000'000;  // PGM's maxval; a million pixels a side
    if (t.empty() || *end != '\0' || v < 1 || v > limit)
      return Bad(
          file, line,
          std::string("PGM ") + names[f] + " '" + t + "' is not 1.." + std::to_string(limit));
    *fields[f] = static_cast<int>(v);
  }
  const std::size_t n = static_cast<std::size_t>(p.width) * p.height;
  p.pixels.resize(n);
  if (magic == "P5") {
    ++pos;  // the single whitespace after maxval
    const std::size_t bpp = p.maxval < 256 ? 1 : 2;
    if (bytes.size() - std::min(pos, bytes.size()) < n * bpp)
      return Bad(file, line,
                 "the image ends after " +
                     std::to_string((bytes.size() - std::min(pos, bytes.size())) / bpp) + " of " +
                     std::to_string(n) + " pixels");
    for (std::size_t k = 0; k < n; ++k) {
      const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + pos + k * bpp);
      p.pixels[k] = bpp == 1 ? b[0] : (b[0] << 8 | b[1]);  // 16-bit PGM is big-endian
    }
  } else {
    for (std::size_t k = 0; k < n; ++k) {
      const std::string t = token();
      char* end = nullptr;
      const long v = std::strtol(t.c_str(), &end, 10);
      if (t.empty())
        return Bad(
            file, token_line,
            "the image ends after " + std::to_string(k) + " of " + std::to_string(n) + " pixels");
      if (*end != '\0' || v < 0 || v > p.maxval)
        return Bad(file, line, "pixel '" + t + "' is not 0.." + std::to_string(p.maxval));
      p.pixels[k] = static_cast<int>(v);
    }
  }
  for (const int v : p.pixels)
    if (v > p.maxval) return Bad(file, line, "a pixel exceeds maxval " + std::to_string(p.maxval));
  return p;
}

// map_server's reading of one pixel (see the header).
std::int8_t Occupancy(int pixel, int maxval, const MapYaml& y) {
  if (y.mode == Mode::kRaw)
    return pixel <= 100 ? static_cast<std::int8_t>(pixel) : kOccupancyUnknown;
  const double p = y.negate ? double(pixel) / maxval : double(maxval - pixel) / maxval;
  if (p > y.occupied_thresh) return kOccupancyLethal;
  if (p < y.free_thresh) return 0;
  if (y.mode == Mode::kTrinary) return kOccupancyUnknown;
  return static_cast<std::int8_t>(
      std::lround(99 * (p - y.free_thresh) / (y.occupied_thresh - y.free_thresh)));
}

}  // namespace

Result<OccupancyGrid> LoadOccupancyGrid(const std::string& yaml_path) {
  const Result<std::string> text = ReadFile(yaml_path, "map_server YAML");
  if (!text) return tl::make_unexpected(text.error());
  const Result<MapYaml> y = ParseMapYaml(*text, yaml_path);
  if (!y) return tl::make_unexpected(y.error());
  fs::path image = y->image;
  if (image.is_relative()) image = fs::path(yaml_path).parent_path() / image;
  const Result<std::string> bytes = ReadFile(image.string(), "map image");
  if (!bytes) return tl::make_unexpected(bytes.error());
  const Result<Pgm> pgm = ParsePgm(*bytes, image.string());
  if (!pgm) return tl::make_unexpected(pgm.error());
  OccupancyGrid grid;
  grid.geometry = {y->origin[0], y->origin[1], y->resolution, pgm->width, pgm->height};
  grid.value.resize(grid.geometry.cell_count());
  for (int row = 0; row < pgm->height; ++row)  // image row 0 is the northern (top) row
    for (int col = 0; col < pgm->width; ++col)
      grid.value[grid.geometry.Linear({col, pgm->height - 1 - row})] =
          Occupancy(pgm->pixels[static_cast<std::size_t>(row) * pgm->width + col], pgm->maxval, *y);
  return grid;
}

Result<void> WriteOccupancyGrid(const OccupancyGrid& grid, const std::string& yaml_path) {
  const mapping::GridGeometry& g = grid.geometry;
  const fs::path pgm_path = fs::path(yaml_path).replace_extension(".pgm");
  std::string pgm = "P5\n" + std::to_string(g.size_x) + " " + std::to_string(g.size_y) + "\n255\n";
  pgm.reserve(pgm.size() + g.cell_count());
  for (int j = g.size_y - 1; j >= 0; --j)  // north row first
    for (int i = 0; i < g.size_x; ++i) {
      const std::int8_t v = grid.value[g.Linear({i, j})];
      pgm += static_cast<char>(v < 0 ? 255 : v);  // raw: 0..100, 255 unknown
    }
  char yaml[512];
  std::snprintf(yaml, sizeof(yaml),
                "# map_server occupancy grid written by pitchlab, raw mode: 0 free, 1..99 the\n"
                "# planner's cost of entering the cell (99: a cell at the robot's limits), 100\n"
                "# lethal (step, drop, too steep), 255 unknown. Nav2's static layer reads the\n"
                "# costs with trinary_costmap: false. The thresholds (map_saver's defaults) are\n"
                "# required keys, unused in raw mode.\n"
                "image: %s\nresolution: %.9g\norigin: [%.9g, %.9g, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: raw\n",
                pgm_path.filename().string().c_str(), g.cell_m, g.x_min_m, g.y_min_m);
  if (auto r = mapping::WriteFileAtomically(pgm_path.string(), pgm); !r) return r;
  return mapping::WriteFileAtomically(yaml_path, yaml);
}

}  // namespace pitchlab::planning
