#include "cloud_input.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mission/registration_json.hpp"
#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::apps {

sensors::Scan3D LoadInputCloud(const std::string& path,
                               const std::optional<Eigen::Vector3d>& sensor_origin_override,
                               bool set_lines_right, nlohmann::json* line_pitch) {
  Result<sensors::Scan3D> scan = sensors::ReadCloudFile(path);
  if (!scan) throw std::runtime_error(scan.error().message);
  if (sensor_origin_override) {
    sensors::SetSensorOrigin(*scan, *sensor_origin_override);
  } else if (!scan->sensor_origin) {
    std::cerr << "warning: '" << path << "' does not say where its sensor stood; assuming the "
              << "origin of its points' frame (give it with --sensor-origin x,y,z [m])\n";
    sensors::SetSensorOrigin(*scan, Eigen::Vector3d::Zero());
  }
  if (set_lines_right) {
    mapping::PointCloud points = mapping::CloudFromScan(*scan);
    const mapping::LinePitch r =
        mapping::RectifyLinePitch(points, scan->sensor_origin->cast<float>());
    for (std::size_t k = 0; k < points.size(); ++k) {
      scan->points[k].x = points[k].x();
      scan->points[k].y = points[k].y();
      scan->points[k].z = points[k].z();
    }
    if (r.corrected > 0) {
      constexpr double kToDeg = 180 / 3.14159265358979323846;
      // An interlaced line's sweeps are set right each on its own (LinePitchConfig).
      const std::string what = r.sweeps_per_line > 1
                                   ? std::to_string(r.lines * r.sweeps_per_line) + " sweeps (" +
                                         std::to_string(r.sweeps_per_line) +
                                         " interlaced in each of " + std::to_string(r.lines) +
                                         " lines)"
                                   : std::to_string(r.lines) + " lines";
      std::fprintf(stderr,
                   "%s: %zu of %s set right by the floor they crossed (pitch corrections "
                   "%.2f deg RMS, at most %.2f; floor %.1f -> %.1f mm RMS)\n",
                   path.c_str(), r.corrected, what.c_str(), r.rms_correction_rad * kToDeg,
                   r.max_correction_rad * kToDeg, r.floor_rms_before_m * 1e3,
                   r.floor_rms_after_m * 1e3);
    }
    if (line_pitch) *line_pitch = mission::LinePitchJson(r);
  } else if (line_pitch) {
    *line_pitch = {{"corrected", 0}, {"note", "--as-recorded"}};
  }
  return std::move(*scan);
}

Eigen::Vector3d ParseSensorOrigin(const std::string& text) {
  std::vector<double> numbers;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v)) {
      throw CliError("--sensor-origin '" + text + "': '" + item + "' is not a finite number");
    }
    numbers.push_back(v);
  }
  if (numbers.size() != 3 || (!text.empty() && text.back() == ',')) {
    throw CliError("--sensor-origin '" + text + "' needs three comma-separated numbers x,y,z [m]");
  }
  return Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
}

std::optional<Eigen::Vector3d> SensorOriginOption(const CliArgs& args) {
  if (!args.Has("sensor-origin")) return std::nullopt;
  return ParseSensorOrigin(args.Get("sensor-origin"));
}

std::optional<std::pair<double, double>> PriorErrorOption(const CliArgs& args) {
  if (!args.Has("prior-error")) return std::nullopt;
  const std::vector<double> e = args.GetNumbers("prior-error", 2);
  if (!(e[0] >= 0 && e[1] >= 0 && std::isfinite(e[0]) && std::isfinite(e[1]))) {
    throw CliError("--prior-error: metres and degrees must be finite and >= 0");
  }
  return std::pair{e[0], e[1]};
}

}  // namespace pitchlab::apps
