// ESRI ASCII grid reader (dem_io.hpp): strict, every error names the file and the line.

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {
namespace {

// A header field's value and the line it stood on.
struct Field {
  double value = 0;
  int line = 0;
};

// The whole token is one finite number.
bool ParseNumber(const std::string& token, double* value) {
  if (token.empty()) return false;
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  return errno == 0 && end == token.c_str() + token.size() && std::isfinite(*value);
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool IsHeaderKey(const std::string& key) {
  static const char* const kKeys[] = {"ncols",     "nrows",     "xllcorner", "xllcenter",
                                      "yllcorner", "yllcenter", "cellsize",  "nodata_value"};
  for (const char* k : kKeys)
    if (key == k) return true;
  return false;
}

// The grid's size and placement from its header fields, or the first thing wrong with them.
// `end` is the line the header ended on: where a missing field should have been.
Result<AsciiGrid> GridFromHeader(const std::map<std::string, Field>& h, const std::string& where,
                                 int end) {
  const auto bad = [&](int line, const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, where + ":" + std::to_string(line) + ": " + why);
  };
  for (const char* key : {"ncols", "nrows", "cellsize"})
    if (!h.count(key)) return bad(end, std::string("missing header field '") + key + "'");
  AsciiGrid g;
  for (const char* key : {"ncols", "nrows"}) {
    const Field& f = h.at(key);
    // 1e8 cells a side: beyond any DEM a file of text holds, and the product fits 64 bits.
    if (!(f.value >= 1 && f.value <= 1e8 && f.value == std::floor(f.value)))
      return bad(f.line, std::string("'") + key + "' must be a whole number >= 1, not " +
                             NumberText(f.value));
  }
  g.ncols = static_cast<int>(h.at("ncols").value);
  g.nrows = static_cast<int>(h.at("nrows").value);
  g.cell_size = g.cell_size_y = h.at("cellsize").value;
  if (!(g.cell_size > 0))
    return bad(h.at("cellsize").line,
               "'cellsize' must be positive, not " + NumberText(g.cell_size));
  for (const std::string axis : {"x", "y"}) {
    const bool corner = h.count(axis + "llcorner"), centre = h.count(axis + "llcenter");
    if (corner == centre)
      return bad(end, "give exactly one of '" + axis + "llcorner' and '" + axis + "llcenter'");
    // A centre reference lies half a cell inside the corner.
    const double v =
        corner ? h.at(axis + "llcorner").value : h.at(axis + "llcenter").value - 0.5 * g.cell_size;
    (axis == "x" ? g.xll_corner : g.yll_corner) = v;
  }
  if (h.count("nodata_value")) g.nodata_value = h.at("nodata_value").value;
  return g;
}

}  // namespace

Result<AsciiGrid> ReadAsciiGrid(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    return Fail(Error::Code::kNotFound,
                path + ": cannot open the ESRI ASCII grid: " + std::strerror(errno));
  const auto bad = [&](int line, const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, path + ":" + std::to_string(line) + ": " + why);
  };
  std::map<std::string, Field> header;
  std::string line, first_data;
  int number = 0, first_data_line = 0;
  while (std::getline(in, line)) {  // header: `key value` lines up to the first number
    ++number;
    std::istringstream tokens(line);
    std::string key, value_text, extra;
    if (!(tokens >> key)) continue;
    const std::string lower = Lower(key);
    double value = 0;
    if (!IsHeaderKey(lower)) {  // a word is a header field misspelt; anything else, data
      if (std::isalpha(static_cast<unsigned char>(key[0])) && !ParseNumber(key, &value))
        return bad(number, "'" + key +
                               "' is neither a header field (ncols, nrows, xllcorner, "
                               "yllcorner, cellsize, NODATA_value) nor a number");
      first_data = line, first_data_line = number;
      break;
    }
    if (!(tokens >> value_text) || !ParseNumber(value_text, &value) || (tokens >> extra))
      return bad(number, "header field '" + key + "' needs one finite number: '" + line + "'");
    if (header.count(lower)) return bad(number, "header field '" + key + "' is given twice");
    header[lower] = {value, number};
  }
  const int grid_line = first_data_line ? first_data_line : number;
  Result<AsciiGrid> grid = GridFromHeader(header, path, grid_line);
  if (!grid) return grid;
  const std::size_t expected = static_cast<std::size_t>(grid->ncols) * grid->nrows;
  // Each value takes a byte and a separator at least: a header that asks for more values than the
  // file can hold is wrong, and is said before its count is allocated (10^16 cells, 80 PB).
  std::error_code size_error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, size_error);
  if (!size_error && expected > file_bytes / 2 + 1)
    return bad(grid_line, "nrows x ncols = " + std::to_string(grid->nrows) + " x " +
                              std::to_string(grid->ncols) + " = " + std::to_string(expected) +
                              " values, more than the file's " + std::to_string(file_bytes) +
                              " bytes can hold");
  grid->values.reserve(expected);
  const auto consume = [&](const std::string& text, int at) -> Result<void> {
    std::istringstream tokens(text);
    std::string token;
    while (tokens >> token) {
      double v = 0;
      if (!ParseNumber(token, &v)) return bad(at, "'" + token + "' is not a finite number");
      if (grid->values.size() == expected)
        return bad(at, "more values than nrows x ncols = " + std::to_string(expected));
      const bool nodata = grid->nodata_value && v == *grid->nodata_value;
      grid->values.push_back(nodata ? std::numeric_limits<double>::quiet_NaN() : v);
    }
    return {};
  };
  if (first_data_line > 0) {
    if (auto r = consume(first_data, first_data_line); !r) return tl::make_unexpected(r.error());
  }
  while (std::getline(in, line)) {
    if (auto r = consume(line, ++number); !r) return tl::make_unexpected(r.error());
  }
  if (grid->values.size() != expected)
    return bad(number, "nrows x ncols = " + std::to_string(grid->nrows) + " x " +
                           std::to_string(grid->ncols) + " = " + std::to_string(expected) +
                           " values expected, the file ends after " +
                           std::to_string(grid->values.size()));
  return grid;
}

}  // namespace pitchlab::mapping
