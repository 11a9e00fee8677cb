#include "cloud_input.hpp"

#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::apps {

sensors::Scan3D LoadInputCloud(const std::string& path,
                               const std::optional<Eigen::Vector3d>& sensor_origin_override) {
  Result<sensors::Scan3D> scan = sensors::ReadCloudFile(path);
  if (!scan) throw std::runtime_error(scan.error().message);
  if (sensor_origin_override) {
    sensors::SetSensorOrigin(*scan, *sensor_origin_override);
  } else if (!scan->sensor_origin) {
    std::cerr << "warning: '" << path << "' does not say where its sensor stood; assuming the "
              << "origin of its points' frame (give it with --sensor-origin x,y,z [m])\n";
    sensors::SetSensorOrigin(*scan, Eigen::Vector3d::Zero());
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
