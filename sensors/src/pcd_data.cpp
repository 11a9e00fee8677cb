#include "pcd_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>

#include "cloud_text.hpp"

namespace pitchlab::sensors::detail {
namespace {

tl::unexpected<Error> Corrupt(const std::string& path, const std::string& why) {
  return Fail(Error::Code::kInvalidArgument, "PCD '" + path + "' is corrupt: " + why);
}

// `value` stored as a field value of `type` and `size` bytes at `to`; false when it is not one
// (a fraction or out of range for an integer; any number, nan and inf included, for a float).
bool Store(double value, char type, int size, std::uint8_t* to) {
  const auto put = [to](auto v) {
    std::memcpy(to, &v, sizeof(v));
    return true;
  };
  if (type == 'F') return size == 4 ? put(static_cast<float>(value)) : put(value);
  if (!std::isfinite(value) || value != std::floor(value)) return false;
  const auto in = [value](auto lo, auto hi) {
    return value >= static_cast<double>(lo) && value <= static_cast<double>(hi);
  };
  if (type == 'U') {
    switch (size) {
      case 1:
        return in(0, UINT8_MAX) && put(static_cast<std::uint8_t>(value));
      case 2:
        return in(0, UINT16_MAX) && put(static_cast<std::uint16_t>(value));
      case 4:
        return in(0, UINT32_MAX) && put(static_cast<std::uint32_t>(value));
      default:
        return value >= 0 && value < 1.8446744073709552e19 &&
               put(static_cast<std::uint64_t>(value));
    }
  }
  switch (size) {
    case 1:
      return in(INT8_MIN, INT8_MAX) && put(static_cast<std::int8_t>(value));
    case 2:
      return in(INT16_MIN, INT16_MAX) && put(static_cast<std::int16_t>(value));
    case 4:
      return in(INT32_MIN, INT32_MAX) && put(static_cast<std::int32_t>(value));
    default:
      return value >= -9.2233720368547758e18 && value < 9.2233720368547758e18 &&
             put(static_cast<std::int64_t>(value));
  }
}

// Lines of the header before the data: to name an ascii data line by its line in the file.
std::size_t HeaderLines(std::ifstream& in, std::uint64_t data_offset) {
  std::string head(data_offset, '\0');
  in.seekg(0);
  in.read(head.data(), static_cast<std::streamsize>(data_offset));
  return static_cast<std::size_t>(std::count(head.begin(), head.end(), '\n'));
}

Result<std::vector<std::uint8_t>> ReadAscii(std::ifstream& in, const std::string& path,
                                            const PcdHeader& h) {
  std::size_t values = 0;
  for (const PcdField& f : h.fields) values += static_cast<std::size_t>(f.count);
  std::vector<std::uint8_t> records(h.points * h.point_step);
  std::size_t line_number = HeaderLines(in, h.data_offset);
  in.seekg(static_cast<std::streamoff>(h.data_offset));
  std::uint64_t point = 0;
  for (std::string line; point < h.points && std::getline(in, line);) {
    ++line_number;
    if (IsBlankOrComment(line)) continue;
    const std::vector<std::string_view> tokens = SplitFields(line);
    if (tokens.size() != values) {
      return Corrupt(path, "line " + std::to_string(line_number) + " has " +
                               std::to_string(tokens.size()) + " values, its FIELDS hold " +
                               std::to_string(values));
    }
    std::uint8_t* to = records.data() + point * h.point_step;
    std::size_t t = 0;
    for (const PcdField& f : h.fields) {
      for (int c = 0; c < f.count; ++c, ++t, to += f.size) {
        const std::optional<double> v = ParseNumber(tokens[t]);
        if (!v || !Store(*v, f.type, f.size, to)) {
          return Corrupt(path, "line " + std::to_string(line_number) + ": '" +
                                   std::string(tokens[t]) + "' is no value of field '" + f.name +
                                   "' (TYPE " + f.type + ", SIZE " + std::to_string(f.size) + ")");
        }
      }
    }
    ++point;
  }
  if (point < h.points) {
    return Corrupt(path, "the header promises " + std::to_string(h.points) +
                             " points, its data lines hold " + std::to_string(point));
  }
  return records;
}

}  // namespace

bool LzfDecompress(const std::uint8_t* in, std::size_t in_size, std::vector<std::uint8_t>& out) {
  const std::uint8_t* ip = in;
  const std::uint8_t* const in_end = in + in_size;
  std::size_t op = 0;
  const std::size_t out_size = out.size();
  while (ip < in_end) {
    const unsigned ctrl = *ip++;
    if (ctrl < 32) {  // a literal run of ctrl + 1 bytes
      const std::size_t n = ctrl + 1;
      if (n > static_cast<std::size_t>(in_end - ip) || n > out_size - op) return false;
      std::memcpy(out.data() + op, ip, n);
      ip += n;
      op += n;
      continue;
    }
    // A back reference: length (ctrl >> 5, extended by a byte when 7) + 2, distance from the
    // low 5 bits and the next byte, + 1.
    std::size_t length = ctrl >> 5;
    if (ip >= in_end) return false;
    if (length == 7) {
      length += *ip++;
      if (ip >= in_end) return false;
    }
    length += 2;
    const std::size_t distance = ((ctrl & 0x1fu) << 8) + *ip++ + 1;
    if (distance > op || length > out_size - op) return false;
    for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - distance];  // may overlap
  }
  return op == out_size;
}

Result<std::vector<std::uint8_t>> ReadPcdRecords(const std::string& path, const PcdHeader& h) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Fail(Error::Code::kNotFound, "cannot read PCD '" + path + "'");
  if (h.data == PcdData::kAscii) return ReadAscii(in, path, h);
  const std::uint64_t bytes = h.points * h.point_step;  // within the file: CheckPcdDataSize
  std::vector<std::uint8_t> records(bytes);
  in.seekg(static_cast<std::streamoff>(h.data_offset));
  if (h.data == PcdData::kBinary) {
    if (!in.read(reinterpret_cast<char*>(records.data()), static_cast<std::streamsize>(bytes))) {
      return Corrupt(path, "its binary data ends early");
    }
    return records;
  }
  std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed: checked by CheckPcdDataSize
  std::vector<std::uint8_t> packed;
  if (in.read(reinterpret_cast<char*>(sizes), sizeof(sizes))) {
    packed.resize(sizes[0]);
    in.read(reinterpret_cast<char*>(packed.data()), static_cast<std::streamsize>(sizes[0]));
  }
  if (!in || sizes[1] != bytes) return Corrupt(path, "its binary_compressed data ends early");
  std::vector<std::uint8_t> by_field(bytes);
  if (!LzfDecompress(packed.data(), packed.size(), by_field)) {
    return Corrupt(path, "its binary_compressed data does not decompress to " +
                             std::to_string(bytes) + " bytes");
  }
  // Compressed, each field's values of all points lie together: interleave them into records.
  std::size_t field_start = 0, offset = 0;
  for (const PcdField& f : h.fields) {
    const std::size_t width = static_cast<std::size_t>(f.size) * f.count;
    for (std::uint64_t i = 0; i < h.points; ++i) {
      std::memcpy(records.data() + i * h.point_step + offset,
                  by_field.data() + field_start + i * width, width);
    }
    field_start += width * h.points;
    offset += width;
  }
  return records;
}

}  // namespace pitchlab::sensors::detail
