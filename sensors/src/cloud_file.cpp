// ReadCloudFile: picks the reader by the file's extension.

#include "pitchlab/sensors/cloud_file.hpp"

#include "cloud_text.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"

namespace pitchlab::sensors {

const char* CloudFormatsHelp() {
  return "  .pcd        PCL point cloud (ascii/binary); VIEWPOINT = pose of the points' frame\n"
         "  .3d         3DTK \"uos\" scan (cm, left-handed), with its .pose beside it\n"
         "  .ply        PLY (ascii, binary little/big endian): the vertex x y z\n"
         "  .xyz .txt   text, one point a line: x y z [m] (spaces, tabs or commas)\n";
}

Result<Scan3D> ReadCloudFile(const std::string& path) {
  const std::string ext = detail::LowerExtension(path);
  if (ext == ".pcd") return ReadScanPcd(path);
  if (ext == ".3d") return Read3dtkScan(path);
  if (ext == ".ply") return ReadPly(path);
  if (ext == ".xyz" || ext == ".txt") return ReadXyz(path);
  return Fail(Error::Code::kInvalidArgument, "'" + path + "': unknown point-cloud format '" + ext +
                                                 "' (known: .pcd, .3d, .ply, .xyz, .txt)");
}

void SetSensorOrigin(Scan3D& scan, const Eigen::Vector3d& origin_m) {
  scan.sensor_origin = origin_m;
  for (ScanPoint& p : scan.points) {
    p.range_m = static_cast<float>((Eigen::Vector3d(p.x, p.y, p.z) - origin_m).norm());
  }
}

}  // namespace pitchlab::sensors
