#include "pitchlab/worlds/esri_grid.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace pitchlab::worlds {
namespace {

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// Strict number parsing: the whole token must be a finite number.
bool ParseNumber(const std::string& token, double& value) {
  if (token.empty()) return false;
  errno = 0;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return errno == 0 && end == token.c_str() + token.size() && std::isfinite(value);
}

[[noreturn]] void Fail(const std::string& source, int line, const std::string& problem) {
  std::ostringstream message;
  message << source;
  if (line > 0) message << ":" << line;
  message << ": " << problem;
  throw std::runtime_error(message.str());
}

bool IsHeaderKey(const std::string& key) {
  static const char* kKeys[] = {"ncols",     "nrows",     "xllcorner", "xllcenter",
                                "yllcorner", "yllcenter", "cellsize",  "nodata_value"};
  return std::find(std::begin(kKeys), std::end(kKeys), key) != std::end(kKeys);
}

// Header values by lower-case key, with the line each came from.
struct Header {
  std::map<std::string, std::pair<double, int>> fields;
  bool Has(const std::string& key) const { return fields.count(key) > 0; }
  double Get(const std::string& key) const { return fields.at(key).first; }
};

int RequireCount(const Header& header, const std::string& key, const std::string& source) {
  if (!header.Has(key)) Fail(source, 0, "missing header field '" + key + "'");
  const auto [value, line] = header.fields.at(key);
  if (value < 1 || value != std::floor(value) || value > 1e8) {
    Fail(source, line,
         "header field '" + key + "' must be a positive integer, got " + std::to_string(value));
  }
  return static_cast<int>(value);
}

double RequireCorner(const Header& header, const std::string& axis, double cell,
                     const std::string& source) {
  const bool corner = header.Has(axis + "llcorner");
  const bool center = header.Has(axis + "llcenter");
  if (corner == center) {
    Fail(source, 0, "need exactly one of '" + axis + "llcorner' and '" + axis + "llcenter'");
  }
  // A cell-centre reference sits half a cell inside the corner.
  return corner ? header.Get(axis + "llcorner") : header.Get(axis + "llcenter") - 0.5 * cell;
}

EsriGrid MakeGrid(const Header& header, const std::string& source) {
  EsriGrid grid;
  grid.ncols = RequireCount(header, "ncols", source);
  grid.nrows = RequireCount(header, "nrows", source);
  if (!header.Has("cellsize")) Fail(source, 0, "missing header field 'cellsize'");
  grid.cell_size = header.Get("cellsize");
  if (!(grid.cell_size > 0.0)) {
    Fail(source, header.fields.at("cellsize").second,
         "header field 'cellsize' must be positive, got " + std::to_string(grid.cell_size));
  }
  grid.cell_size_y = grid.cell_size;
  grid.xll_corner = RequireCorner(header, "x", grid.cell_size, source);
  grid.yll_corner = RequireCorner(header, "y", grid.cell_size, source);
  if (header.Has("nodata_value")) grid.nodata_value = header.Get("nodata_value");
  return grid;
}

}  // namespace

EsriGrid ParseEsriGrid(std::istream& in, const std::string& source) {
  Header header;
  std::string line;
  int line_number = 0;
  std::vector<std::pair<std::string, int>> pending;  // first data tokens met while reading header
  // Header: "key value" lines until the first line that does not start with a known key.
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream tokens(line);
    std::string key, value_text, extra;
    if (!(tokens >> key)) continue;
    const std::string lower = Lower(key);
    if (!IsHeaderKey(lower)) {
      pending.emplace_back(line, line_number);
      break;
    }
    double value = 0.0;
    if (!(tokens >> value_text) || !ParseNumber(value_text, value) || (tokens >> extra)) {
      Fail(source, line_number, "header field '" + key + "' needs one number, got '" + line + "'");
    }
    if (header.Has(lower)) Fail(source, line_number, "duplicate header field '" + key + "'");
    header.fields[lower] = {value, line_number};
  }
  if (header.fields.empty()) Fail(source, 0, "missing header (ncols, nrows, ...)");
  EsriGrid grid = MakeGrid(header, source);

  const size_t expected = static_cast<size_t>(grid.ncols) * grid.nrows;
  // Reserved up to a million values: the header's count is the file's word (up to 10^16).
  grid.values.reserve(std::min<size_t>(expected, size_t{1} << 20));
  auto consume = [&](const std::string& text, int number) {
    std::istringstream tokens(text);
    std::string token;
    while (tokens >> token) {
      double value = 0.0;
      if (!ParseNumber(token, value)) {
        Fail(source, number, "non-numeric value '" + token + "'");
      }
      if (grid.values.size() == expected) {
        Fail(source, number, "more values than nrows x ncols = " + std::to_string(expected));
      }
      const bool nodata = grid.nodata_value && value == *grid.nodata_value;
      grid.values.push_back(nodata ? std::numeric_limits<double>::quiet_NaN() : value);
    }
  };
  for (const auto& [text, number] : pending) consume(text, number);
  while (std::getline(in, line)) consume(line, ++line_number);
  if (grid.values.size() != expected) {
    Fail(source, line_number,
         "expected nrows x ncols = " + std::to_string(grid.nrows) + " x " +
             std::to_string(grid.ncols) + " = " + std::to_string(expected) + " values, found " +
             std::to_string(grid.values.size()));
  }
  return grid;
}

EsriGrid CropToArea(const EsriGrid& grid, const GridArea& area) {
  // Columns and rows whose centres lie within the area (row 0 northernmost), inclusive: a centre
  // on the area's edge (a round longitude on a 3" grid) counts. A millionth of a cell: headers
  // round the cell size (SRTM's 1/1200 deg as 0.000833333333), 60 cells on 2.4e-8 cells off.
  constexpr double kOnEdge = 1e-6;  // [cell]
  const auto first = [](double index) { return static_cast<int>(std::ceil(index - kOnEdge)); };
  const auto last = [](double index) { return static_cast<int>(std::floor(index + kOnEdge)); };
  const double top = grid.yll_corner + grid.nrows * grid.cell_size_y;
  const int col0 = std::max(0, first((area.x_min - grid.xll_corner) / grid.cell_size - 0.5));
  const int col1 =
      std::min(grid.ncols - 1, last((area.x_max - grid.xll_corner) / grid.cell_size - 0.5));
  const int row0 = std::max(0, first((top - area.y_max) / grid.cell_size_y - 0.5));
  const int row1 = std::min(grid.nrows - 1, last((top - area.y_min) / grid.cell_size_y - 0.5));
  if (!(area.x_min < area.x_max && area.y_min < area.y_max) || col1 - col0 < 1 || row1 - row0 < 1) {
    std::ostringstream os;
    os.precision(10);
    os << "the area x " << area.x_min << " .. " << area.x_max << ", y " << area.y_min << " .. "
       << area.y_max << " holds fewer than 2 x 2 of the grid's cell centres (the grid spans x "
       << grid.ColumnX(0) << " .. " << grid.ColumnX(grid.ncols - 1) << ", y "
       << grid.RowY(grid.nrows - 1) << " .. " << grid.RowY(0) << " between cell centres)";
    throw std::invalid_argument(os.str());
  }
  EsriGrid crop;  // not a copy of the grid: a DEM tile's values run to a few hundred MB
  crop.ncols = col1 - col0 + 1;
  crop.nrows = row1 - row0 + 1;
  crop.xll_corner = grid.xll_corner + col0 * grid.cell_size;
  crop.yll_corner = grid.yll_corner + (grid.nrows - 1 - row1) * grid.cell_size_y;
  crop.cell_size = grid.cell_size;
  crop.cell_size_y = grid.cell_size_y;
  crop.nodata_value = grid.nodata_value;
  crop.values.reserve(static_cast<std::size_t>(crop.ncols) * crop.nrows);
  for (int row = row0; row <= row1; ++row) {
    const auto first = grid.values.begin() + static_cast<std::ptrdiff_t>(row) * grid.ncols;
    crop.values.insert(crop.values.end(), first + col0, first + col1 + 1);
  }
  return crop;
}

EsriGrid LoadEsriGrid(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open ESRI ASCII grid");
  return ParseEsriGrid(in, path.string());
}

bool HasGeographicPrj(const std::filesystem::path& asc_path) {
  std::filesystem::path prj = asc_path;
  prj.replace_extension(".prj");
  std::ifstream in(prj);
  if (!in) return false;
  std::stringstream text;
  text << in.rdbuf();
  const std::string wkt = text.str();
  return wkt.find("GEOGCS") != std::string::npos && wkt.find("PROJCS") == std::string::npos;
}

}  // namespace pitchlab::worlds
