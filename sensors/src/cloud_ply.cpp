// PLY clouds (Turk's format as Stanford's, Meshlab's, CloudCompare's and Open3D's writers use it):
// the header names elements and their typed properties; ascii data has one element a line, binary
// data packs them in header order. We keep the vertex element's x y z and skip the rest by size.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cloud_text.hpp"
#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::sensors {
namespace {

enum class Kind { kSigned, kUnsigned, kFloat };
struct Scalar {
  Kind kind = Kind::kFloat;
  int size = 0;  // [bytes]
};

struct Property {
  std::string name;
  Scalar type;                  // the value's type, or a list's item type
  std::optional<Scalar> count;  // set for a list: the type of its length
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kLittle, kBig };

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::optional<Eigen::Vector3d> sensor_origin;
  std::size_t data_offset = 0;  // first byte after the end_header line
  int lines = 0;                // header lines, for ascii line numbers
};

// The PLY scalar types and their aliases (PLY 1.0 names and the sized ones newer writers use).
std::optional<Scalar> ScalarNamed(std::string_view name) {
  struct Entry {
    const char* a;
    const char* b;
    Scalar s;
  };
  static const Entry kTypes[] = {
      {"char", "int8", {Kind::kSigned, 1}},    {"uchar", "uint8", {Kind::kUnsigned, 1}},
      {"short", "int16", {Kind::kSigned, 2}},  {"ushort", "uint16", {Kind::kUnsigned, 2}},
      {"int", "int32", {Kind::kSigned, 4}},    {"uint", "uint32", {Kind::kUnsigned, 4}},
      {"float", "float32", {Kind::kFloat, 4}}, {"double", "float64", {Kind::kFloat, 8}}};
  for (const Entry& e : kTypes) {
    if (name == e.a || name == e.b) return e.s;
  }
  return std::nullopt;
}

tl::unexpected<Error> Bad(const std::string& path, const std::string& what) {
  return Fail(Error::Code::kInvalidArgument, "PLY '" + path + "': " + what);
}

tl::unexpected<Error> BadLine(const std::string& path, int line, const std::string& what) {
  return Bad(path, "line " + std::to_string(line) + ": " + what);
}

// `sensor_origin x y z` in a comment or obj_info line: how pitchlab records the sensor [m].
Result<void> ReadOriginComment(const std::string& path, int line_no,
                               const std::vector<std::string_view>& f, Header& header) {
  if (f.size() < 2 || f[1] != "sensor_origin") return {};
  double v[3];
  for (int i = 0; i < 3; ++i) {
    const std::optional<double> number =
        f.size() == 5 ? detail::ParseNumber(f[2 + i]) : std::nullopt;
    if (!number || !std::isfinite(*number)) {
      return BadLine(path, line_no, "sensor_origin needs three finite numbers x y z [m]");
    }
    v[i] = *number;
  }
  header.sensor_origin = Eigen::Vector3d(v[0], v[1], v[2]);
  return {};
}

Result<void> ReadProperty(const std::string& path, int line_no,
                          const std::vector<std::string_view>& f, Header& header) {
  if (header.elements.empty()) return BadLine(path, line_no, "a property before any element");
  Property p;
  if (f.size() == 5 && f[1] == "list") {
    p.count = ScalarNamed(f[2]);
    const std::optional<Scalar> item = ScalarNamed(f[3]);
    if (!p.count || !item || p.count->kind == Kind::kFloat) {
      return BadLine(path, line_no, "a list property needs an integer count type and an item type");
    }
    p.type = *item;
    p.name = std::string(f[4]);
  } else {
    const std::optional<Scalar> type = f.size() == 3 ? ScalarNamed(f[1]) : std::nullopt;
    if (!type) return BadLine(path, line_no, "expected 'property TYPE NAME' with a PLY type");
    p.type = *type;
    p.name = std::string(f[2]);
  }
  header.elements.back().properties.push_back(p);
  return {};
}

Result<Header> ReadHeader(const std::string& path, const std::string& data) {
  Header header;
  bool has_format = false;
  std::size_t pos = 0;
  while (true) {
    const std::size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) return Bad(path, "the header has no end_header line");
    const std::string_view line(data.data() + pos, eol - pos);
    pos = eol + 1;
    const int line_no = ++header.lines;
    const std::vector<std::string_view> f = detail::SplitFields(line);
    if (line_no == 1) {
      if (f.size() != 1 || f[0] != "ply") return Bad(path, "not a PLY file (no 'ply' first line)");
      continue;
    }
    if (f.empty()) continue;
    if (f[0] == "end_header") break;
    if (f[0] == "comment" || f[0] == "obj_info") {
      if (auto r = ReadOriginComment(path, line_no, f, header); !r) {
        return tl::make_unexpected(r.error());
      }
    } else if (f[0] == "format") {
      if (f.size() != 3 || f[2] != "1.0") {
        return BadLine(path, line_no, "expected 'format TYPE 1.0'");
      }
      if (f[1] == "ascii") {
        header.format = Format::kAscii;
      } else if (f[1] == "binary_little_endian") {
        header.format = Format::kLittle;
      } else if (f[1] == "binary_big_endian") {
        header.format = Format::kBig;
      } else {
        return BadLine(path, line_no, "unknown format '" + std::string(f[1]) + "'");
      }
      has_format = true;
    } else if (f[0] == "element") {
      const std::optional<double> n = f.size() == 3 ? detail::ParseNumber(f[2]) : std::nullopt;
      if (!n || *n < 0 || *n != std::floor(*n) || *n > 9.0e18) {
        return BadLine(path, line_no, "expected 'element NAME COUNT'");
      }
      header.elements.push_back({std::string(f[1]), static_cast<std::uint64_t>(*n), {}});
    } else if (f[0] == "property") {
      if (auto r = ReadProperty(path, line_no, f, header); !r) {
        return tl::make_unexpected(r.error());
      }
    } else {
      return BadLine(path, line_no, "unknown header keyword '" + std::string(f[0]) + "'");
    }
  }
  if (!has_format) return Bad(path, "the header has no format line");
  header.data_offset = pos;
  return header;
}

// Indices of x, y, z among the vertex element's properties, or an error for a file without them.
Result<std::array<int, 3>> VertexXyz(const std::string& path, const Header& header) {
  for (const Element& e : header.elements) {
    if (e.name != "vertex") continue;
    std::array<int, 3> index{-1, -1, -1};
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
      if (axis >= 0 && !p.count) index[axis] = static_cast<int>(i);
    }
    if (*std::min_element(index.begin(), index.end()) >= 0) return index;
  }
  return Bad(path, "no vertex element with x y z properties (faces only?): no points to read");
}

// One binary scalar at `p` as a double, bytes swapped when the file's order is not ours.
double Decode(const char* p, Scalar s, bool swap) {
  unsigned char b[8];
  std::memcpy(b, p, s.size);
  if (swap) std::reverse(b, b + s.size);
  auto as = [&b](auto value) {
    std::memcpy(&value, b, sizeof(value));
    return static_cast<double>(value);
  };
  switch (s.kind) {
    case Kind::kFloat:
      return s.size == 4 ? as(float{}) : as(double{});
    case Kind::kSigned:
      return s.size == 1   ? as(std::int8_t{})
             : s.size == 2 ? as(std::int16_t{})
                           : as(std::int32_t{});
    case Kind::kUnsigned:
      return s.size == 1   ? as(std::uint8_t{})
             : s.size == 2 ? as(std::uint16_t{})
                           : as(std::uint32_t{});
  }
  return 0.0;
}

bool HostIsLittleEndian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// `line_no` 0 for binary data (no lines to name).
Result<void> AddVertex(const std::string& path, std::uint64_t i, const Eigen::Vector3d& v,
                       int line_no, Scan3D& scan) {
  if (!v.allFinite()) {
    const std::string where = line_no > 0 ? "line " + std::to_string(line_no) + ": " : "";
    return Bad(path, where + "vertex " + std::to_string(i) +
                         " (counting from 0) has a coordinate that is not finite");
  }
  scan.points.push_back(detail::MakePoint(v, Eigen::Vector3d::Zero()));
  return {};
}

Result<void> ReadBinary(const std::string& path, const std::string& data, const Header& header,
                        const std::array<int, 3>& xyz, Scan3D& scan) {
  const bool swap = (header.format == Format::kLittle) != HostIsLittleEndian();
  const char* p = data.data() + header.data_offset;
  const char* const end = data.data() + data.size();
  auto truncated = [&](const Element& e, std::uint64_t i) {
    return Bad(path, "the data end inside element '" + e.name + "' " + std::to_string(i) + " of " +
                         std::to_string(e.count) + " (truncated file?)");
  };
  for (const Element& e : header.elements) {
    if (e.properties.empty()) continue;  // holds no bytes, however large its count
    const bool is_vertex = e.name == "vertex" && scan.points.empty();
    if (is_vertex) {  // no more than the bytes left can hold: the count may be a lie
      std::uint64_t min_bytes = 0;
      for (const Property& prop : e.properties)
        min_bytes += prop.count ? prop.count->size : prop.type.size;
      scan.points.reserve(
          std::min<std::uint64_t>(e.count, (end - p) / std::max<std::uint64_t>(min_bytes, 1)));
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      Eigen::Vector3d v;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const Property& prop = e.properties[k];
        std::uint64_t bytes = prop.type.size;
        if (prop.count) {
          if (end - p < prop.count->size) return truncated(e, i);
          const double n = Decode(p, *prop.count, swap);
          if (n < 0) {
            return Bad(path, "element '" + e.name + "' " + std::to_string(i) +
                                 ": a list of negative length");
          }
          p += prop.count->size;
          bytes = static_cast<std::uint64_t>(n) * prop.type.size;
        }
        if (static_cast<std::uint64_t>(end - p) < bytes) return truncated(e, i);
        if (is_vertex) {
          for (int axis = 0; axis < 3; ++axis) {
            if (xyz[axis] == static_cast<int>(k)) v[axis] = Decode(p, prop.type, swap);
          }
        }
        p += bytes;
      }
      if (is_vertex) {
        if (auto r = AddVertex(path, i, v, 0, scan); !r) return r;
      }
    }
  }
  return {};
}

Result<void> ReadAscii(const std::string& path, const std::string& data, const Header& header,
                       const std::array<int, 3>& xyz, Scan3D& scan) {
  std::istringstream in(data.substr(header.data_offset));
  int line_no = header.lines;
  std::string line;
  for (const Element& e : header.elements) {
    if (e.properties.empty()) continue;  // holds no values, so no lines
    const bool is_vertex = e.name == "vertex" && scan.points.empty();
    for (std::uint64_t i = 0; i < e.count; ++i) {
      std::vector<std::string_view> f;
      while (f.empty()) {
        if (!std::getline(in, line)) {
          return Bad(path, "the data end after " + std::to_string(i) + " of " +
                               std::to_string(e.count) + " '" + e.name + "' elements");
        }
        ++line_no;
        f = detail::SplitFields(line);
      }
      std::size_t t = 0;  // next token
      Eigen::Vector3d v;
      auto number = [&](Scalar type) -> Result<double> {
        if (t >= f.size()) {
          return BadLine(path, line_no, "too few values for element '" + e.name + "'");
        }
        const std::optional<double> n = detail::ParseNumber(f[t]);
        if (!n || (type.kind != Kind::kFloat && *n != std::floor(*n))) {
          return BadLine(path, line_no,
                         "'" + std::string(f[t]) + "' is not a valid " +
                             (type.kind == Kind::kFloat ? "number" : "integer"));
        }
        ++t;
        return *n;
      };
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const Property& prop = e.properties[k];
        std::uint64_t n = 1;
        if (prop.count) {
          const Result<double> length = number(*prop.count);
          if (!length) return tl::make_unexpected(length.error());
          if (*length < 0) return BadLine(path, line_no, "a list of negative length");
          n = static_cast<std::uint64_t>(*length);
        }
        for (std::uint64_t j = 0; j < n; ++j) {
          const Result<double> value = number(prop.type);
          if (!value) return tl::make_unexpected(value.error());
          for (int axis = 0; axis < 3; ++axis) {
            if (is_vertex && xyz[axis] == static_cast<int>(k)) v[axis] = *value;
          }
        }
      }
      if (t != f.size()) {
        return BadLine(path, line_no,
                       std::to_string(f.size()) + " values where the header " + "declares " +
                           std::to_string(t) + " for '" + e.name + "'");
      }
      if (is_vertex) {
        if (auto r = AddVertex(path, i, v, line_no, scan); !r) {
          return r;
        }
      }
    }
  }
  return {};
}

}  // namespace

Result<Scan3D> ReadPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!std::filesystem::is_regular_file(path) || !in) {
    return Fail(Error::Code::kNotFound, "cannot read PLY file '" + path + "'");
  }
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return Fail(Error::Code::kFailed, "error reading PLY file '" + path + "'");
  Result<Header> header = ReadHeader(path, data);
  if (!header) return tl::make_unexpected(header.error());
  Result<std::array<int, 3>> xyz = VertexXyz(path, *header);
  if (!xyz) return tl::make_unexpected(xyz.error());
  Scan3D scan;
  const Result<void> body = header->format == Format::kAscii
                                ? ReadAscii(path, data, *header, *xyz, scan)
                                : ReadBinary(path, data, *header, *xyz, scan);
  if (!body) return tl::make_unexpected(body.error());
  if (scan.points.empty()) return Bad(path, "the vertex element holds no points");
  if (header->sensor_origin) SetSensorOrigin(scan, *header->sensor_origin);
  return scan;
}

}  // namespace pitchlab::sensors
