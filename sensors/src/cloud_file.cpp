// ReadCloudFile: picks the reader by the file's extension.

#include "pitchlab/sensors/cloud_file.hpp"

#include <cmath>
#include <sstream>

#include "cloud_text.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"

namespace pitchlab::sensors {

const char* CloudFormatsHelp() {
  return "  .pcd        PCL point cloud (ascii, binary, binary_compressed);\n"
         "              VIEWPOINT = pose of the points' frame\n"
         "  .3d         3DTK \"uos\" scan (cm, left-handed), with its .pose beside it\n"
         "  .ply        PLY (ascii, binary little/big endian): the vertex x y z\n"
         "  .xyz .txt   text, one point a line: x y z [m] (spaces, tabs or commas)\n";
}

namespace {

Result<Scan3D> ReadByExtension(const std::string& path) {
  const std::string ext = detail::LowerExtension(path);
  if (ext == ".pcd") return ReadScanPcd(path);
  if (ext == ".3d") return Read3dtkScan(path);
  if (ext == ".ply") return ReadPly(path);
  if (ext == ".xyz" || ext == ".txt") return ReadXyz(path);
  return Fail(Error::Code::kInvalidArgument, "'" + path + "': unknown point-cloud format '" + ext +
                                                 "' (known: .pcd, .3d, .ply, .xyz, .txt)");
}

}  // namespace

Result<void> CheckPointsPlausible(const Scan3D& scan, const std::string& path) {
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const ScanPoint& p = scan.points[i];
    if (std::abs(p.x) <= kMaxCoordinate_m && std::abs(p.y) <= kMaxCoordinate_m &&
        std::abs(p.z) <= kMaxCoordinate_m) {
      continue;
    }
    std::ostringstream os;
    os << "'" << path << "': point " << i << " at (" << p.x << ", " << p.y << ", " << p.z
       << ") m lies more than 100 km from its frame's origin: a corrupt file, or units other "
          "than metres";
    return Fail(Error::Code::kInvalidArgument, os.str());
  }
  return {};
}

Result<Scan3D> ReadCloudFile(const std::string& path) {
  Result<Scan3D> scan = ReadByExtension(path);
  if (!scan) return scan;
  if (Result<void> plausible = CheckPointsPlausible(*scan, path); !plausible) {
    return tl::make_unexpected(plausible.error());
  }
  return scan;
}

void SetSensorOrigin(Scan3D& scan, const Eigen::Vector3d& origin_m) {
  scan.sensor_origin = origin_m;
  for (ScanPoint& p : scan.points) {
    p.range_m = static_cast<float>((Eigen::Vector3d(p.x, p.y, p.z) - origin_m).norm());
  }
}

}  // namespace pitchlab::sensors
