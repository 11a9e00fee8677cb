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

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include "cloud_text.hpp"
#include "pcd_checks.hpp"
#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::sensors {
namespace {

// One PCD record, packed: PCL would otherwise write the alignment gap as a field named "_".
struct __attribute__((packed)) PackedPoint {
  float x, y, z, range;
  std::uint16_t ring, beam;
  double stamp;
};
static_assert(sizeof(PackedPoint) == 28, "PCD record must have no padding");

pcl::PCLPointField Field(const char* name, std::uint32_t offset, std::uint8_t type) {
  pcl::PCLPointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = type;
  f.count = 1;
  return f;
}

pcl::PCLPointCloud2 ToCloud2(const Scan3D& scan) {
  using F = pcl::PCLPointField;
  pcl::PCLPointCloud2 cloud;
  cloud.fields = {Field("x", offsetof(PackedPoint, x), F::FLOAT32),
                  Field("y", offsetof(PackedPoint, y), F::FLOAT32),
                  Field("z", offsetof(PackedPoint, z), F::FLOAT32),
                  Field("range", offsetof(PackedPoint, range), F::FLOAT32),
                  Field("ring", offsetof(PackedPoint, ring), F::UINT16),
                  Field("beam", offsetof(PackedPoint, beam), F::UINT16),
                  Field("stamp", offsetof(PackedPoint, stamp), F::FLOAT64)};
  cloud.height = 1;
  cloud.width = static_cast<std::uint32_t>(scan.points.size());
  cloud.point_step = sizeof(PackedPoint);
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = true;
  cloud.data.resize(cloud.row_step);
  std::uint8_t* out = cloud.data.data();
  for (const ScanPoint& p : scan.points) {
    const PackedPoint record{p.x, p.y, p.z, p.range_m, p.line, p.beam, p.stamp_s};
    std::memcpy(out, &record, sizeof(record));
    out += sizeof(record);
  }
  return cloud;
}

// pitchlab's header comments (PCL's reader skips lines starting with '#'): where the sensor stood
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
  const fs::path tmp = target.parent_path() / ("." + target.filename().string() + ".tmp" +
                                               std::to_string(::getpid()));
  const Eigen::Vector3d t = scan.T_world_base.translation();
  const Eigen::Quaterniond q(scan.T_world_base.rotation());
  const Eigen::Vector4f origin(float(t.x()), float(t.y()), float(t.z()), 0.0f);
  const pcl::PCLPointCloud2 cloud = ToCloud2(scan);
  // PCL's writer has no place for comments: its header, our lines after its first (comment) line.
  std::string header = pcl::PCDWriter().generateHeaderBinary(cloud, origin, q.cast<float>());
  header.insert(header.find('\n') + 1, HeaderComments(scan));
  header += "DATA binary\n";  // generateHeaderBinary stops before it, as writeBinary adds it
  if (Result<void> written = WriteWhole(tmp, {header, std::string_view(reinterpret_cast<const char*>(
                                                              cloud.data.data()),
                                                          cloud.data.size())});
      !written) {
    return Fail(Error::Code::kFailed, "cannot write PCD '" + path + "': " + written.error().message);
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
  pcl::PCLPointCloud2 cloud;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int pcd_version = 0;
  pcl::PCDReader reader;
  if (!std::filesystem::is_regular_file(path)) {
    return Fail(Error::Code::kNotFound, "no such PCD file '" + path + "'");
  }
  // PCL's reader trusts the header: it allocates what POINTS says, crashes on a compressed size
  // of 0 or a file without fields, leaves a VIEWPOINT "nan" unset. Check it ourselves first.
  Result<detail::PcdHeader> header = detail::PeekPcdHeader(path);
  if (!header) return tl::make_unexpected(header.error());
  if (Result<void> sized = detail::CheckPcdDataSize(path, header->data, header->data_offset,
                                                    header->points, header->point_step);
      !sized) {
    return tl::make_unexpected(sized.error());
  }
  if (Result<void> viewpoint = detail::CheckViewpoint(path, header->origin, header->orientation);
      !viewpoint) {
    return tl::make_unexpected(viewpoint.error());
  }
  int data_type = 0;
  unsigned int data_idx = 0;
  if (reader.readHeader(path, cloud, origin, orientation, pcd_version, data_type, data_idx) != 0 ||
      cloud.fields.empty() || cloud.point_step == 0) {
    return Fail(Error::Code::kInvalidArgument, "'" + path + "' is not a readable PCD file");
  }
  if (reader.read(path, cloud, origin, orientation, pcd_version) != 0) {
    return Fail(Error::Code::kInvalidArgument, "'" + path + "' is not a readable PCD file");
  }
  // A field's offset when it has `name` and one of `types`, else -1.
  auto offset_of = [&](const char* name, std::initializer_list<std::uint8_t> types) -> int {
    for (const auto& f : cloud.fields) {
      for (std::uint8_t type : types) {
        if (f.name == name && f.datatype == type) return static_cast<int>(f.offset);
      }
    }
    return -1;
  };
  using F = pcl::PCLPointField;
  // x y z as float32 (ours, PCL's default) or float64 (Open3D, CloudCompare with doubles).
  const bool doubles = offset_of("x", {F::FLOAT64}) >= 0;
  const std::uint8_t xyz_type = doubles ? F::FLOAT64 : F::FLOAT32;
  const int ox = offset_of("x", {xyz_type}), oy = offset_of("y", {xyz_type}),
            oz = offset_of("z", {xyz_type});
  if (ox < 0 || oy < 0 || oz < 0) {
    return Fail(Error::Code::kInvalidArgument,
                "PCD '" + path + "' has no x y z fields of one float type (4 or 8 bytes)");
  }
  const int orange = offset_of("range", {F::FLOAT32}), oring = offset_of("ring", {F::UINT16}),
            obeam = offset_of("beam", {F::UINT16}), ostamp = offset_of("stamp", {F::FLOAT64});
  Scan3D scan;
  const std::size_t n = std::size_t(cloud.width) * cloud.height;
  scan.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* rec = cloud.data.data() + i * cloud.point_step;
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
      ++scan.no_returns;  // NaN points are how PCL marks missing returns
      continue;
    }
    scan.points.push_back(p);
  }
  if (!scan.points.empty()) scan.stamp_s = scan.points.front().stamp_s;
  scan.T_world_base = Eigen::Isometry3d::Identity();
  // Our reading of the VIEWPOINT, checked above (PCL's leaves values it cannot parse unset).
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
