#include "pitchlab/mapping/tum_trajectory.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

#include "pitchlab/mapping/atomic_file.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {

namespace {

constexpr const char* kHeader = "# timestamp tx ty tz qx qy qz qw\n";

// A quaternion read back from a file printed with 4 decimals per component (as some tools write
// them) is up to ~2e-4 from unit norm; 1e-3 allows that and still refuses a scaled rotation.
constexpr double kQuaternionNormTolerance = 1e-3;

// The shortest text that reads back to the same double (std::to_chars' round-trip guarantee).
void AppendNumber(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, end);
}

Result<void> CheckPose(const StampedPose& p, std::size_t index, double previous_stamp_s) {
  const std::string where = "TUM trajectory: pose " + std::to_string(index);
  if (!std::isfinite(p.stamp_s) || !p.T_map_base.matrix().allFinite()) {
    return Fail(Error::Code::kInvalidArgument, where + " is not finite");
  }
  const Eigen::Matrix3d R = p.T_map_base.linear();
  // 1e-6: a composed rotation stays orthonormal to ~1e-12; this catches a scaled or sheared one.
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0) {
    return Fail(Error::Code::kInvalidArgument, where + " is not a rotation and translation");
  }
  if (index > 0 && !(p.stamp_s > previous_stamp_s)) {
    return Fail(Error::Code::kInvalidArgument, where + ": stamp " + std::to_string(p.stamp_s) +
                                                   " s is not after the previous " +
                                                   std::to_string(previous_stamp_s) + " s");
  }
  return {};
}

// Splits a line at spaces and tabs.
std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string field; in >> field;) out.push_back(field);
  return out;
}

Result<double> ParseNumber(const std::string& field, const std::string& where) {
  double v = 0;
  const char* first = field.data();
  const char* last = first + field.size();
  if (*first == '+') ++first;  // from_chars refuses a leading '+', printf-style writers emit it
  const auto [end, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || end != last) {
    return Fail(Error::Code::kInvalidArgument, where + ": '" + field + "' is not a number");
  }
  if (!std::isfinite(v)) {
    return Fail(Error::Code::kInvalidArgument, where + ": '" + field + "' is not finite");
  }
  return v;
}

Result<StampedPose> ParseLine(const std::vector<std::string>& fields, const std::string& where) {
  if (fields.size() != 8) {
    return Fail(Error::Code::kInvalidArgument,
                where + ": expected 8 numbers (timestamp tx ty tz qx qy qz qw), found " +
                    std::to_string(fields.size()) + " fields");
  }
  double v[8];
  for (int i = 0; i < 8; ++i) {
    const Result<double> number = ParseNumber(fields[i], where);
    if (!number) return tl::make_unexpected(number.error());
    v[i] = *number;
  }
  Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);  // w, x, y, z
  if (std::abs(q.norm() - 1) > kQuaternionNormTolerance) {
    return Fail(Error::Code::kInvalidArgument,
                where + ": quaternion norm " + NumberText(q.norm()) + " is not 1");
  }
  StampedPose p;
  p.stamp_s = v[0];
  p.T_map_base.linear() = q.normalized().toRotationMatrix();
  p.T_map_base.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
  return p;
}

}  // namespace

Result<std::string> FormatTumTrajectory(const std::vector<StampedPose>& poses) {
  std::string out = kHeader;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const StampedPose& p = poses[i];
    if (auto ok = CheckPose(p, i, i > 0 ? poses[i - 1].stamp_s : 0); !ok) {
      return tl::make_unexpected(ok.error());
    }
    Eigen::Quaterniond q(p.T_map_base.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // q and -q are one rotation: write qw >= 0
    const Eigen::Vector3d& t = p.T_map_base.translation();
    const double values[8] = {p.stamp_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
    for (int k = 0; k < 8; ++k) {
      if (k > 0) out += ' ';
      AppendNumber(out, values[k]);
    }
    out += '\n';
  }
  return out;
}

Result<std::vector<StampedPose>> ParseTumTrajectory(const std::string& text,
                                                    const std::string& source) {
  std::vector<StampedPose> out;
  std::istringstream in(text);
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    const std::vector<std::string> fields = Fields(line);
    if (fields.empty() || fields.front().front() == '#') continue;
    const std::string where = source + ":" + std::to_string(line_number);
    Result<StampedPose> pose = ParseLine(fields, where);
    if (!pose) return tl::make_unexpected(pose.error());
    if (!out.empty() && !(pose->stamp_s > out.back().stamp_s)) {
      return Fail(Error::Code::kInvalidArgument,
                  where + ": timestamp " + fields.front() +
                      " is not after the previous pose's (stamps must increase)");
    }
    out.push_back(*pose);
  }
  return out;
}

Result<void> WriteTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses) {
  const Result<std::string> text = FormatTumTrajectory(poses);
  if (!text) return Fail(text.error().code, path + ": " + text.error().message);
  return WriteFileAtomically(path, *text);
}

Result<std::vector<StampedPose>> ReadTumTrajectory(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return Fail(Error::Code::kInvalidArgument, path + ": is a directory, not a TUM trajectory");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Fail(Error::Code::kNotFound, path + ": cannot read: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Fail(Error::Code::kFailed, path + ": read failed");
  return ParseTumTrajectory(text.str(), path);
}

}  // namespace pitchlab::mapping
