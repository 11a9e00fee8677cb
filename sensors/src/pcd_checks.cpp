#include "pcd_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "cloud_text.hpp"

#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors::detail {
namespace {

// A PCD's quaternion is written from a unit one in float32 (PCL) or with a few decimals by hand
// ("0.7071 0 0 0.7071" is 0.99999 long); 1 % off unit is neither, and 0 is no rotation at all.
constexpr double kQuaternionNormTolerance = 0.01;
// The most values one field may hold per point [1].
constexpr double kMaxCount = 1 << 20;
// LZF makes at most 264 bytes of 3 (a back reference of the longest length), so a stream of n
// bytes decompresses to at most 88 n: a larger stated size is a damaged or crafted header.
constexpr std::uint64_t kLzfMaxRatio = 88;

tl::unexpected<Error> Corrupt(const std::string& path, const std::string& why) {
  return Fail(Error::Code::kInvalidArgument, "PCD '" + path + "' is corrupt: " + why);
}

// The numbers of one header line after its keyword, or nullopt when one is not a number.
std::optional<std::vector<double>> Numbers(const std::vector<std::string_view>& fields) {
  std::vector<double> numbers;
  for (std::size_t i = 1; i < fields.size(); ++i) {
    const std::optional<double> v = ParseNumber(fields[i]);
    if (!v) return std::nullopt;
    numbers.push_back(*v);
  }
  return numbers;
}

std::uint64_t FileSize(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  return ec ? 0 : static_cast<std::uint64_t>(size);
}

}  // namespace

Result<PcdHeader> PeekPcdHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Fail(Error::Code::kNotFound, "cannot read PCD '" + path + "'");
  PcdHeader h;
  std::vector<double> sizes, counts;
  std::vector<std::string> names;
  std::vector<char> type_codes;
  std::size_t fields = 0, types = 0;
  std::optional<double> width, height, points;
  for (std::string line; std::getline(in, line);) {
    const std::vector<std::string_view> f = SplitFields(line);
    if (f.empty() || f[0].front() == '#') continue;
    const std::optional<std::vector<double>> v = Numbers(f);
    if (f[0] == "DATA") {
      if (f.size() < 2) break;
      // What PCL's readHeader would only print about before failing: say it in the error.
      for (const auto& [what, n] : {std::pair{"SIZE", sizes.size()},
                                    {"TYPE", types == 0 ? fields : types},
                                    {"COUNT", counts.empty() ? fields : counts.size()}}) {
        if (n != fields) {
          return Fail(Error::Code::kInvalidArgument, "PCD '" + path + "': " + what + " has " +
                                                         std::to_string(n) + " entries for " +
                                                         std::to_string(fields) + " FIELDS");
        }
      }
      if (f[1] != "ascii" && f[1] != "binary" && f[1] != "binary_compressed") {
        return Fail(Error::Code::kInvalidArgument,
                    "PCD '" + path + "': DATA '" + std::string(f[1]) +
                        "' is none of ascii, binary, binary_compressed");
      }
      h.data = f[1] == "binary"              ? PcdData::kBinary
               : f[1] == "binary_compressed" ? PcdData::kBinaryCompressed
                                             : PcdData::kAscii;
      // The file may end with the DATA line, without a newline: no data after it, then.
      const std::streamoff after = in.tellg();
      h.data_offset = after >= 0 ? static_cast<std::uint64_t>(after) : FileSize(path);
      const std::uint64_t counted = points ? *points : width.value_or(0) * height.value_or(1);
      h.points = counted;
      for (std::size_t i = 0; i < fields; ++i) {
        // Within int before the casts: SIZE is at most 8, COUNT (a descriptor's length, 308 for
        // PCL's VFH) bounded far above any writer's.
        const double size = sizes[i] >= 1 && sizes[i] <= 8 ? sizes[i] : 0;
        const double count = counts.empty()                             ? 1
                             : counts[i] >= 1 && counts[i] <= kMaxCount ? counts[i]
                                                                        : 0;
        PcdField field{names[i], static_cast<int>(size), type_codes.empty() ? 'F' : type_codes[i],
                       static_cast<int>(count)};
        const bool known_size = field.type == 'F' ? (field.size == 4 || field.size == 8)
                                                  : (field.type == 'U' || field.type == 'I') &&
                                                        (field.size == 1 || field.size == 2 ||
                                                         field.size == 4 || field.size == 8);
        if (!known_size || sizes[i] != field.size || field.count < 1 ||
            (counts.size() > i && counts[i] != field.count)) {
          return Fail(Error::Code::kInvalidArgument,
                      "PCD '" + path + "': field '" + field.name + "' of TYPE " + field.type +
                          ", SIZE " + std::to_string(sizes[i]) + ", COUNT " +
                          std::to_string(counts.empty() ? 1.0 : counts[i]) +
                          " is none a PCD holds (F 4 or 8 bytes; U or I 1, 2, 4 or 8; COUNT >= 1)");
        }
        h.point_step += static_cast<std::uint64_t>(field.size) * field.count;
        h.fields.push_back(std::move(field));
      }
      return h;
    }
    if (f[0] == "VIEWPOINT") {
      if (!v || v->size() != 7) {
        return Fail(Error::Code::kInvalidArgument,
                    "PCD '" + path + "': '" + line + "' is not 'VIEWPOINT tx ty tz qw qx qy qz'");
      }
      const std::vector<double>& n = *v;
      h.origin = Eigen::Vector4f(float(n[0]), float(n[1]), float(n[2]), 0.0f);
      h.orientation = Eigen::Quaternionf(float(n[3]), float(n[4]), float(n[5]), float(n[6]));
    }
    // Counts beyond 2^64 or negative are not PCD headers: PCL would wrap them.
    const auto count = [&](std::optional<double>& into) -> bool {
      if (!v || v->size() != 1 || !((*v)[0] >= 0 && (*v)[0] < 1.8e19)) return false;
      into = (*v)[0];
      return true;
    };
    if ((f[0] == "WIDTH" && !count(width)) || (f[0] == "HEIGHT" && !count(height)) ||
        (f[0] == "POINTS" && !count(points))) {
      return Fail(Error::Code::kInvalidArgument,
                  "PCD '" + path + "': '" + line + "' is not a count of points");
    }
    if (f[0] == "FIELDS") {
      fields = f.size() - 1;
      names.assign(f.begin() + 1, f.end());
    }
    if (f[0] == "TYPE") {
      types = f.size() - 1;
      type_codes.clear();
      for (std::size_t i = 1; i < f.size(); ++i)
        type_codes.push_back(f[i].size() == 1 ? f[i][0] : '?');
    }
    if (f[0] == "SIZE" && v) sizes = *v;
    if (f[0] == "COUNT" && v) counts = *v;
  }
  return Fail(Error::Code::kInvalidArgument, "'" + path + "' is not a PCD file (no DATA line)");
}

Result<void> CheckPcdDataSize(const std::string& path, PcdData type, std::uint64_t data_offset,
                              std::uint64_t points, std::uint64_t point_step) {
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) return Fail(Error::Code::kNotFound, "cannot read PCD '" + path + "': " + ec.message());
  const std::uint64_t available = file_size > data_offset ? file_size - data_offset : 0;
  // The reader allocates points x point_step bytes before it reads a byte of data, so the count
  // must fit the file: binary holds point_step bytes a point, ascii at least 2 (a digit and a separator),
  // binary_compressed at most 4 GiB uncompressed (its size word has 32 bits).
  const std::uint64_t step = std::max<std::uint64_t>(point_step, 1);
  const std::uint64_t capacity = type == PcdData::kBinary  ? available / step
                                 : type == PcdData::kAscii ? available / 2
                                                           : UINT32_MAX / step;
  if (points > capacity) {
    if (type == PcdData::kBinary) {
      return Fail(Error::Code::kInvalidArgument,
                  "PCD '" + path + "' is truncated: the header promises " + std::to_string(points) +
                      " points of " + std::to_string(point_step) + " bytes, the file holds " +
                      std::to_string(available) + " bytes of data");
    }
    return Corrupt(path, "the header promises " + std::to_string(points) +
                             " points, more than its " + std::to_string(available) +
                             " bytes of data can hold");
  }
  const std::uint64_t data_bytes = points * point_step;  // <= capacity x step: no overflow
  if (type != PcdData::kBinaryCompressed) return {};
  // binary_compressed: two uint32 words (compressed size, uncompressed size), then the LZF data.
  std::uint32_t sizes[2] = {0, 0};
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(data_offset));
  if (available < sizeof(sizes) || !in.read(reinterpret_cast<char*>(sizes), sizeof(sizes))) {
    return Corrupt(path, "binary_compressed data has no size words");
  }
  if (sizes[0] > available - sizeof(sizes)) {
    return Corrupt(path, "its compressed size " + std::to_string(sizes[0]) +
                             " bytes exceeds the file's remaining " +
                             std::to_string(available - sizeof(sizes)));
  }
  if (sizes[1] > kLzfMaxRatio * std::uint64_t{sizes[0]}) {
    return Corrupt(path, "its uncompressed size " + std::to_string(sizes[1]) +
                             " bytes is more than LZF makes of " + std::to_string(sizes[0]));
  }
  if (sizes[1] != data_bytes) {
    return Corrupt(path, "its uncompressed size " + std::to_string(sizes[1]) +
                             " bytes is not the header's " + std::to_string(points) + " points x " +
                             std::to_string(point_step) + " bytes");
  }
  return {};
}

Result<void> CheckViewpoint(const std::string& path, const Eigen::Vector4f& origin,
                            const Eigen::Quaternionf& orientation) {
  const Eigen::Vector3d t = origin.head<3>().cast<double>();
  const Eigen::Vector4d q = orientation.coeffs().cast<double>();
  auto text = [](const auto& v) {
    std::ostringstream os;
    for (int i = 0; i < v.size(); ++i) os << (i ? " " : "") << v[i];
    return os.str();
  };
  if (!t.allFinite() || t.cwiseAbs().maxCoeff() > kMaxCoordinate_m) {
    return Fail(Error::Code::kInvalidArgument,
                "PCD '" + path + "': VIEWPOINT translation (" + text(t) +
                    ") is not a finite position within 100 km of the origin [m]");
  }
  if (!q.allFinite() || std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
    const Eigen::Vector4d wxyz(q.w(), q.x(), q.y(), q.z());
    return Fail(Error::Code::kInvalidArgument,
                "PCD '" + path + "': VIEWPOINT quaternion (" + text(wxyz) +
                    ") is not a rotation (a unit quaternion w x y z)");
  }
  return {};
}

}  // namespace pitchlab::sensors::detail
