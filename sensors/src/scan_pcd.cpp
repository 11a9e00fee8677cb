#include "pitchlab/sensors/scan_pcd.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <locale>
#include <optional>
#include <sstream>
#include <string_view>

#include "cloud_text.hpp"
#include "pcd_checks.hpp"
#include "pcd_data.hpp"
#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::sensors {
namespace {

// One PCD record, packed (FIELDS x y z range ring beam stamp).
struct __attribute__((packed)) PackedPoint {
  float x, y, z, range;
  std::uint16_t ring, beam;
  double stamp;
};
static_assert(sizeof(PackedPoint) == 28, "PCD record must have no padding");

std::string Records(const Scan3D& scan) {
  std::string data(scan.points.size() * sizeof(PackedPoint), '\0');
  char* out = data.data();
  for (const ScanPoint& p : scan.points) {
    const PackedPoint record{p.x, p.y, p.z, p.range_m, p.line, p.beam, p.stamp_s};
    std::memcpy(out, &record, sizeof(record));
    out += sizeof(record);
  }
  return data;
}

// The header up to its DATA line as PCL's writer makes it (the VIEWPOINT's floats at the stream's
// 6 digits), with pitchlab's comments after its first line.
std::string Header(const Scan3D& scan, const std::string& comments) {
  const Eigen::Vector3f t = scan.T_world_base.translation().cast<float>();
  const Eigen::Quaternionf q = Eigen::Quaterniond(scan.T_world_base.rotation()).cast<float>();
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << "# .PCD v0.7 - Point Cloud Data file format\n"
     << comments << "VERSION 0.7\n"
     << "FIELDS x y z range ring beam stamp\n"
     << "SIZE 4 4 4 4 2 2 8\n"
     << "TYPE F F F F U U F\n"
     << "COUNT 1 1 1 1 1 1 1\n"
     << "WIDTH " << scan.points.size() << "\nHEIGHT 1\n"
     << "VIEWPOINT " << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.w() << ' ' << q.x() << ' '
     << q.y() << ' ' << q.z() << "\n"
     << "POINTS " << scan.points.size() << "\nDATA binary\n";
  return os.str();
}

// pitchlab's header comments (PCD readers skip lines starting with '#'): where the sensor stood
// and what the VIEWPOINT pose is.
constexpr const char* kOriginKey = "# sensor_origin";
constexpr const char* kPoseKey = "# pose";
constexpr const char* kWorldKey = "# world";

std::string HeaderComments(const Scan3D& scan) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(17);  // doubles round-trip
  if (scan.sensor_origin) {
    const Eigen::Vector3d& o = *scan.sensor_origin;
    os << kOriginKey << ' ' << o.x() << ' ' << o.y() << ' ' << o.z() << '\n';
  }
  const char* pose = scan.has_truth ? "truth" : scan.has_odometry ? "odometry" : "unknown";
  os << kPoseKey << ' ' << pose << '\n';
  // One word (a file stem): a world name with spaces would not read back as one field.
  if (!scan.world.empty() && scan.world.find_first_of(" \t\r\n") == std::string::npos) {
    os << kWorldKey << ' ' << scan.world << '\n';
  }
  return os.str();
}

struct Comments {
  std::optional<Eigen::Vector3d> sensor_origin;
  std::optional<std::string> pose;
  std::string world;
};

// Our comment lines among the header's (up to the DATA line).
Result<Comments> ReadComments(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  Comments c;
  for (std::string line; std::getline(in, line) && line.rfind("DATA", 0) != 0;) {
    const std::vector<std::string_view> f = detail::SplitFields(line);
    if (line.rfind(kOriginKey, 0) == 0 && f.size() >= 2 && f[1] == "sensor_origin") {
      Eigen::Vector3d o;
      for (int i = 0; i < 3; ++i) {
        const std::optional<double> v =
            f.size() == 5 ? detail::ParseNumber(f[2 + i]) : std::nullopt;
        if (!v || !std::isfinite(*v)) {
          return Fail(Error::Code::kInvalidArgument,
                      "PCD '" + path + "': '" + line + "' is not 'sensor_origin x y z' [m]");
        }
        o[i] = *v;
      }
      c.sensor_origin = o;
    } else if (line.rfind(kPoseKey, 0) == 0 && f.size() == 3 && f[1] == "pose") {
      c.pose = std::string(f[2]);
    } else if (line.rfind(kWorldKey, 0) == 0 && f.size() == 3 && f[1] == "world") {
      c.world = std::string(f[2]);
    }
  }
  return c;
}

// Writes the parts to a new file `path` with write(2), so a full disk or a file-size limit is an
// error with its reason (ENOSPC, EFBIG) rather than a stream's bare failure bit; a failure removes
// the file.
Result<void> WriteWhole(const std::filesystem::path& path,
                        std::initializer_list<std::string_view> parts) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Fail(Error::Code::kFailed, std::strerror(errno));
  int error = 0;
  for (std::string_view part : parts) {
    while (!part.empty() && error == 0) {
      const ssize_t n = ::write(fd, part.data(), part.size());
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error = n < 0 ? errno : ENOSPC;
        break;
      }
      part.remove_prefix(static_cast<std::size_t>(n));
    }
  }
  if (::close(fd) != 0 && error == 0) error = errno;  // NFS and quotas report on close
  if (error == 0) return {};
  ::unlink(path.c_str());
  return Fail(Error::Code::kFailed, std::strerror(error));
}

}  // namespace

Result<void> WriteScanPcd(const Scan3D& scan, const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = target.parent_path() /
                       ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
  const std::string header = Header(scan, HeaderComments(scan));
  if (Result<void> written = WriteWhole(tmp, {header, Records(scan)}); !written) {
    return Fail(Error::Code::kFailed,
                "cannot write PCD '" + path + "': " + written.error().message);
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Fail(Error::Code::kFailed, "cannot write PCD '" + path + "': " + ec.message());
  }
  return {};
}

Result<Scan3D> ReadScanPcd(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    return Fail(Error::Code::kNotFound, "no such PCD file '" + path + "'");
  }
  Result<detail::PcdHeader> header = detail::PeekPcdHeader(path);
  if (!header) return tl::make_unexpected(header.error());
  if (header->fields.empty() || header->point_step == 0) {
    return Fail(Error::Code::kInvalidArgument, "'" + path + "' is not a readable PCD file");
  }
  if (Result<void> sized = detail::CheckPcdDataSize(path, header->data, header->data_offset,
                                                    header->points, header->point_step);
      !sized) {
    return tl::make_unexpected(sized.error());
  }
  if (Result<void> viewpoint = detail::CheckViewpoint(path, header->origin, header->orientation);
      !viewpoint) {
    return tl::make_unexpected(viewpoint.error());
  }
  Result<std::vector<std::uint8_t>> records = detail::ReadPcdRecords(path, *header);
  if (!records) return tl::make_unexpected(records.error());
  // A field's byte offset in the record when it has `name`, one value of `type` and `size`
  // bytes; else -1.
  auto offset_of = [&](const char* name, char type, int size) -> int {
    std::size_t offset = 0;
    for (const detail::PcdField& f : header->fields) {
      if (f.name == name && f.type == type && f.size == size && f.count == 1) {
        return static_cast<int>(offset);
      }
      offset += static_cast<std::size_t>(f.size) * f.count;
    }
    return -1;
  };
  // x y z as float32 (ours, PCL's default) or float64 (Open3D, CloudCompare with doubles).
  const bool doubles = offset_of("x", 'F', 8) >= 0;
  const int xyz_size = doubles ? 8 : 4;
  const int ox = offset_of("x", 'F', xyz_size), oy = offset_of("y", 'F', xyz_size),
            oz = offset_of("z", 'F', xyz_size);
  if (ox < 0 || oy < 0 || oz < 0) {
    return Fail(Error::Code::kInvalidArgument,
                "PCD '" + path + "' has no x y z fields of one float type (4 or 8 bytes)");
  }
  const int orange = offset_of("range", 'F', 4), oring = offset_of("ring", 'U', 2),
            obeam = offset_of("beam", 'U', 2), ostamp = offset_of("stamp", 'F', 8);
  Scan3D scan;
  const std::size_t n = header->points;
  scan.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* rec = records->data() + i * header->point_step;
    auto get = [rec](int off, auto& value) {
      if (off >= 0) std::memcpy(&value, rec + off, sizeof(value));
    };
    ScanPoint p;
    if (doubles) {
      double x = 0, y = 0, z = 0;
      get(ox, x);
      get(oy, y);
      get(oz, z);
      p.x = static_cast<float>(x), p.y = static_cast<float>(y), p.z = static_cast<float>(z);
    } else {
      get(ox, p.x);
      get(oy, p.y);
      get(oz, p.z);
    }
    get(orange, p.range_m);
    get(oring, p.line);
    get(obeam, p.beam);
    get(ostamp, p.stamp_s);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++scan.no_returns;  // NaN points are how PCD writers mark missing returns
      continue;
    }
    scan.points.push_back(p);
  }
  if (!scan.points.empty()) scan.stamp_s = scan.points.front().stamp_s;
  scan.T_world_base = Eigen::Isometry3d::Identity();
  // The VIEWPOINT, checked above.
  scan.T_world_base.translate(header->origin.head<3>().cast<double>());
  scan.T_world_base.rotate(header->orientation.cast<double>().normalized());
  Result<Comments> comments = ReadComments(path);
  if (!comments) return tl::make_unexpected(comments.error());
  scan.world = comments->world;
  if (comments->pose) {
    scan.has_truth = *comments->pose == "truth";
    scan.has_odometry = *comments->pose == "odometry";
  } else {  // a PCD from elsewhere (or from pitchlab before the comment): simulation's convention
    scan.has_truth = !scan.T_world_base.isApprox(Eigen::Isometry3d::Identity());
  }
  if (comments->sensor_origin) {
    scan.sensor_origin = comments->sensor_origin;
  } else if (!comments->pose) {
    // A PCD from elsewhere: the PCD convention, VIEWPOINT is the acquisition viewpoint, so the
    // sensor stood at the origin of the points' frame.
    scan.sensor_origin = Eigen::Vector3d::Zero();
  }  // else ours, written without an origin (a merged map): it stays unknown
  // Ranges stay as the scanner measured them (from the mirror as it pitched); a file without a
  // range field gets each point's distance from the sensor.
  if (orange < 0 && scan.sensor_origin) SetSensorOrigin(scan, *scan.sensor_origin);
  return scan;
}

}  // namespace pitchlab::sensors
