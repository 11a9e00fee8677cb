#include "pitchlab/mission/app_config.hpp"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace pitchlab::mission {
namespace {

// Top-level sections any pitchlab module reads; anything else is a typo worth an error.
const std::set<std::string> kSections = {
    "seed",  "robot",        "odometry",  "imu",     "lms200", "pitch_unit", "scan",
    "mount", "registration", "elevation", "planner", "run",    "backend",    "hw"};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument("cannot read config file '" + path + "'");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

void ReadRobot(const YAML::Node& node, const std::string& source, sim::RobotConfig& robot) {
  if (!node) return;
  if (!node.IsMap()) throw std::invalid_argument(source + ": 'robot' must be a map");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (key != "model") {
      throw std::invalid_argument(source + ": robot." + key + " is not a known setting");
    }
    const std::string model = kv.second.as<std::string>();
    if (model == "p3at") {
      robot.model = sim::P3Model::kP3AT;
    } else if (model == "p3dx") {
      robot.model = sim::P3Model::kP3DX;
    } else {
      throw std::invalid_argument(source + ": robot.model = '" + model +
                                  "' is not a robot (p3at, p3dx)");
    }
  }
}

void ReadOdometry(const YAML::Node& node, const std::string& source, sim::OdometryConfig& odo) {
  if (!node) return;
  if (!node.IsMap()) throw std::invalid_argument(source + ": 'odometry' must be a map");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    double* field = key == "scale_sigma"       ? &odo.scale_sigma
                    : key == "increment_sigma" ? &odo.increment_sigma
                    : key == "track_error"     ? &odo.track_error
                                               : nullptr;
    if (field == nullptr) {
      throw std::invalid_argument(source + ": odometry." + key +
                                  " is not a known setting (scale_sigma, increment_sigma, "
                                  "track_error)");
    }
    try {
      *field = kv.second.as<double>();
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(source + ": odometry." + key + " must be a number");
    }
  }
}

void ReadImu(const YAML::Node& node, const std::string& source, sim::ImuConfig& imu) {
  if (!node) return;
  if (!node.IsMap()) throw std::invalid_argument(source + ": 'imu' must be a map");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    try {
      if (key == "deskew") {
        imu.deskew = kv.second.as<bool>();
      } else if (key == "deskew_min_deg") {
        imu.deskew_min_deg = kv.second.as<double>();
      } else if (key == "gyro_bias_dps") {
        imu.gyro_bias_dps = kv.second.as<double>();
      } else if (key == "gyro_noise_dps_rthz") {
        imu.gyro_noise_dps_rthz = kv.second.as<double>();
      } else {
        throw std::invalid_argument(source + ": imu." + key +
                                    " is not a known setting (deskew, deskew_min_deg, "
                                    "gyro_bias_dps, gyro_noise_dps_rthz)");
      }
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(
          source + ": imu." + key +
          (key == "deskew" ? " must be true or false" : " must be a number"));
    }
  }
}

}  // namespace

AppConfig LoadAppConfig(const std::optional<std::string>& path) {
  AppConfig config;
  std::string text;
  if (path) {
    text = ReadFile(*path);
    config.source = *path;
  }
  const std::string& source = config.source;
  config.sensors = sensors::ParseSensorConfig(text, source);  // also checks the YAML parses
  const YAML::Node root = text.empty() ? YAML::Node() : YAML::Load(text);
  if (root && !root.IsNull()) {
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      if (!kSections.count(key)) {
        throw std::invalid_argument(source + ": unknown section '" + key + "'");
      }
    }
    if (root["seed"]) {
      try {
        config.seed = root["seed"].as<std::uint64_t>();
      } catch (const YAML::Exception&) {
        throw std::invalid_argument(source + ": seed must be a non-negative integer");
      }
    }
  }
  sim::SimRigConfig& rig = config.rig;
  ReadRobot(root["robot"], source, rig.robot);
  ReadOdometry(root["odometry"], source, rig.odometry);
  ReadImu(root["imu"], source, rig.imu);
  // One seed drives every random source unless a section sets its own.
  if (!(root["lms200"] && root["lms200"]["seed"])) config.sensors.lms200.seed = config.seed;
  if (!(root["pitch_unit"] && root["pitch_unit"]["seed"])) {
    config.sensors.pitch_unit.seed = config.seed;
  }
  rig.odometry.seed = config.seed;
  rig.imu.seed = config.seed;
  rig.lms200 = config.sensors.lms200;
  rig.pitch_unit = config.sensors.pitch_unit;
  rig.pattern = config.sensors.scan;
  rig.robot.mount = config.sensors.mount;
  try {
    rig.robot.Validate();
    rig.odometry.Validate();
    rig.imu.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + e.what());
  }
  return config;
}

std::string AppConfigToYaml(const AppConfig& config) {
  std::ostringstream os;
  os.precision(17);
  const sim::SimRigConfig& rig = config.rig;
  os << "# pitchlab configuration as used (from " << config.source << ")\n"
     << "seed: " << config.seed << "\n"
     << "robot:\n  model: " << (rig.robot.model == sim::P3Model::kP3AT ? "p3at" : "p3dx") << "\n"
     << "odometry:\n"
     << "  scale_sigma: " << rig.odometry.scale_sigma << "\n"
     << "  increment_sigma: " << rig.odometry.increment_sigma << "\n"
     << "  track_error: " << rig.odometry.track_error << "\n"
     << "imu:\n"
     << "  deskew: " << (rig.imu.deskew ? "true" : "false") << "\n"
     << "  deskew_min_deg: " << rig.imu.deskew_min_deg << "\n"
     << "  gyro_bias_dps: " << rig.imu.gyro_bias_dps << "\n"
     << "  gyro_noise_dps_rthz: " << rig.imu.gyro_noise_dps_rthz << "\n"
     << sensors::SensorConfigToYaml(config.sensors);
  return os.str();
}

}  // namespace pitchlab::mission
