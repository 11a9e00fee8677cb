// 3DTK ("uos") scans and slam6d poses, converted to REP-103 metres. The format as 3DTK reads it
// is summed up in tests/data/real/3dtk_corridor/SOURCES.md.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include <Eigen/Geometry>

#include "cloud_text.hpp"
#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::sensors {
namespace {

constexpr double kCmToM = 0.01;
// A reading at the scanner's maximum range code, 3276 cm (3DTK's config.ini: max=3276), is a
// no-return. Written as six significant digits per coordinate, such readings come back at
// 3275.89-3276.7 cm in the corridor scans; anything within 1 cm of the code is that code (the
// LMS measures 1 cm steps in cm mode, and 32.75 m is beyond what it returns off a wall).
constexpr double kNoReturnCm = 3275.0;
// 3DTK's config.ini: min=48 cm. Closer "returns" hit the robot itself, or are the scanner's
// zero-range error codes (the corridor scans hold ~2200 of them at 9-45 cm).
constexpr double kMinRangeCm = 48.0;
// slam6d writes matrices with six significant digits: a rotation's entries are off by <= 5e-7,
// R^T R by ~1e-6. 1e-4 leaves a margin of 100 and still rejects anything that is not a rotation.
constexpr double kRotationTolerance = 1e-4;

// 3DTK (x right, y up, z forward, left-handed) -> REP-103 (x forward, y left, z up).
Eigen::Matrix3d AxisChange() {
  Eigen::Matrix3d C;
  C << 0, 0, 1,  //
      -1, 0, 0,  //
      0, 1, 0;
  return C;
}

tl::unexpected<Error> FailAt(const std::string& path, int line, const std::string& what) {
  return Fail(Error::Code::kInvalidArgument,
              "'" + path + "' line " + std::to_string(line) + ": " + what);
}

// The first `count` fields of `fields` as finite numbers, or the reason they are not.
std::optional<std::string> ParseFinite(const std::vector<std::string_view>& fields,
                                       std::size_t count, double* out) {
  if (fields.size() < count) {
    return "needs " + std::to_string(count) + " numbers, found " + std::to_string(fields.size());
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::optional<double> v = detail::ParseNumber(fields[i]);
    if (!v) return "'" + std::string(fields[i]) + "' is not a number";
    if (!std::isfinite(*v)) return "'" + std::string(fields[i]) + "' is not a finite number";
    out[i] = *v;
  }
  return std::nullopt;
}

// 3DTK's optional first line "<columns> x <rows>" (uosHeaderTest in 3DTK's scanio).
bool IsUosHeader(const std::vector<std::string_view>& fields) {
  return fields.size() == 3 && fields[1] == "x" && detail::ParseNumber(fields[0]) &&
         detail::ParseNumber(fields[2]);
}

}  // namespace

Eigen::Vector3d PointFrom3dtk(const Eigen::Vector3d& p_cm) { return AxisChange() * p_cm * kCmToM; }

Eigen::Isometry3d TransformFrom3dtk(const Eigen::Matrix4d& T_cm) {
  const Eigen::Matrix3d C = AxisChange();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = C * T_cm.topLeftCorner<3, 3>() * C.transpose();  // C^-1 = C^T: C is orthogonal
  T.translation() = C * T_cm.topRightCorner<3, 1>() * kCmToM;
  return T;
}

Eigen::Matrix4d Matrix3dtkFromPose(const Eigen::Vector3d& t_cm, const Eigen::Vector3d& r_deg) {
  const Eigen::Vector3d r = r_deg * (M_PI / 180.0);
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = (Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  T.topRightCorner<3, 1>() = t_cm;
  return T;
}

Result<Eigen::Isometry3d> Read3dtkPose(const std::string& path) {
  std::ifstream in(path);
  if (!std::filesystem::is_regular_file(path) || !in) {
    return Fail(Error::Code::kNotFound, "cannot read 3DTK pose file '" + path + "'");
  }
  std::vector<std::string> words;
  for (std::string word; in >> word && words.size() < 6;) words.push_back(word);
  const std::vector<std::string_view> fields(words.begin(), words.end());
  double v[6];
  if (const auto why = ParseFinite(fields, 6, v)) {
    return Fail(Error::Code::kInvalidArgument,
                "3DTK pose file '" + path + "' (x y z [cm] rx ry rz [deg]): " + *why);
  }
  return TransformFrom3dtk(
      Matrix3dtkFromPose(Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d(v[3], v[4], v[5])));
}

Result<Eigen::Isometry3d> Read3dtkFrames(const std::string& path) {
  std::ifstream in(path);
  if (!std::filesystem::is_regular_file(path) || !in) {
    return Fail(Error::Code::kNotFound, "cannot read slam6d frames file '" + path + "'");
  }
  std::optional<Eigen::Matrix4d> last;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (detail::IsBlankOrComment(line)) continue;
    double v[16];
    if (const auto why = ParseFinite(detail::SplitFields(line), 16, v)) {
      return FailAt(path, line_no, "a 4x4 matrix (16 numbers, column-major) " + *why);
    }
    const Eigen::Matrix4d T = Eigen::Map<const Eigen::Matrix4d>(v);  // Eigen's default: columns
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), kRotationTolerance) ||
        R.determinant() < 0 || !T.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) {
      return FailAt(path, line_no, "the matrix is not a rigid transform");
    }
    last = T;
  }
  if (!last) {
    return Fail(Error::Code::kInvalidArgument, "slam6d frames file '" + path + "' is empty");
  }
  Eigen::Matrix4d T = *last;  // re-orthonormalized: the six printed digits leave R off by ~1e-6
  T.topLeftCorner<3, 3>() =
      Eigen::Quaterniond(T.topLeftCorner<3, 3>()).normalized().toRotationMatrix();
  return TransformFrom3dtk(T);
}

Result<Scan3D> Read3dtkScan(const std::string& path) {
  namespace fs = std::filesystem;
  std::ifstream in(path);
  if (!fs::is_regular_file(path) || !in) {
    return Fail(Error::Code::kNotFound, "cannot read 3DTK scan file '" + path + "'");
  }
  const std::string pose_path = fs::path(path).replace_extension(".pose").string();
  if (!fs::exists(pose_path)) {
    return Fail(Error::Code::kNotFound, "3DTK scan '" + path + "' has no pose: looked for '" +
                                            pose_path + "' (3DTK keeps scanNNN.pose beside it)");
  }
  Result<Eigen::Isometry3d> pose = Read3dtkPose(pose_path);
  if (!pose) return tl::make_unexpected(pose.error());

  Scan3D scan;
  std::size_t readings = 0;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (detail::IsBlankOrComment(line)) continue;
    const std::vector<std::string_view> fields = detail::SplitFields(line);
    if (readings == 0 && IsUosHeader(fields)) continue;
    double v[3];
    if (const auto why = ParseFinite(fields, 3, v)) {
      return FailAt(path, line_no, "x y z [cm] " + *why);
    }
    ++readings;
    const Eigen::Vector3d p_cm(v[0], v[1], v[2]);
    const double r_cm = p_cm.norm();
    if (r_cm > kNoReturnCm) {
      ++scan.no_returns;
    } else if (r_cm > kMinRangeCm) {
      scan.points.push_back(detail::MakePoint(PointFrom3dtk(p_cm), Eigen::Vector3d::Zero()));
    }
  }
  if (in.bad()) return Fail(Error::Code::kFailed, "error reading 3DTK scan '" + path + "'");
  if (readings == 0) {
    return Fail(Error::Code::kInvalidArgument, "3DTK scan '" + path + "' holds no points");
  }
  scan.T_world_base = *pose;
  scan.has_odometry = true;
  scan.sensor_origin = Eigen::Vector3d::Zero();  // 3DTK scans are in the scanner's own frame
  return scan;
}

}  // namespace pitchlab::sensors
