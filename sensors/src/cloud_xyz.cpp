// Plain-text clouds: one point a line, x y z in metres.

#include <cmath>
#include <filesystem>
#include <fstream>

#include "cloud_text.hpp"
#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::sensors {
namespace {

// CloudCompare writes its column header as a "//X Y Z ..." line.
bool IsSlashComment(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t");
  return first != std::string_view::npos && line.substr(first, 2) == "//";
}

}  // namespace

Result<Scan3D> ReadXyz(const std::string& path) {
  std::ifstream in(path);
  if (!std::filesystem::is_regular_file(path) || !in) {
    return Fail(Error::Code::kNotFound, "cannot read point file '" + path + "'");
  }
  Scan3D scan;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (detail::IsBlankOrComment(line) || IsSlashComment(line)) continue;
    const std::vector<std::string_view> fields = detail::SplitFields(line);
    auto fail = [&](const std::string& what) {
      return Fail(Error::Code::kInvalidArgument,
                  "'" + path + "' line " + std::to_string(line_no) + ": " + what);
    };
    if (fields.size() < 3) {
      return fail("needs x y z [m], found " + std::to_string(fields.size()) + " value(s)");
    }
    double v[3];
    for (int i = 0; i < 3; ++i) {
      const std::optional<double> number = detail::ParseNumber(fields[i]);
      if (!number) return fail("'" + std::string(fields[i]) + "' is not a number (x y z [m])");
      if (!std::isfinite(*number)) return fail("'" + std::string(fields[i]) + "' is not finite");
      v[i] = *number;
    }
    scan.points.push_back(
        detail::MakePoint(Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d::Zero()));
  }
  if (in.bad()) return Fail(Error::Code::kFailed, "error reading point file '" + path + "'");
  if (scan.points.empty()) {
    return Fail(Error::Code::kInvalidArgument, "point file '" + path + "' holds no points");
  }
  return scan;  // sensor_origin stays unset: plain text does not say where the sensor was
}

}  // namespace pitchlab::sensors
