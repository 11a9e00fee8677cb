#include "pitchlab/sensors/sensor_config.hpp"
#include "pitchlab/sensors/yaml_keys.hpp"

#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace pitchlab::sensors {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Reads the keys of one section into fields; anything else in the section is an error.
class SectionReader {
 public:
  SectionReader(const YAML::Node& root, const char* section, const std::string& source)
      : node_(root[section]), section_(section), source_(source) {}

  template <typename T>
  SectionReader& Field(const char* key, T& value) {
    handlers_[key] = [this, key, &value](const YAML::Node& n) {
      try {
        value = n.as<T>();
      } catch (const YAML::Exception&) {
        Throw(key, "has the wrong type ('" + Scalar(n) + "')");
      }
    };
    return *this;
  }

  void Read() const {
    if (!node_) return;
    if (!node_.IsMap()) throw std::invalid_argument(source_ + ": '" + section_ + "' must be a map");
    for (const auto& kv : node_) {
      const std::string key = kv.first.as<std::string>();
      auto it = handlers_.find(key);
      if (it == handlers_.end()) Throw(key.c_str(), "is not a known setting");
      it->second(kv.second);
    }
  }

  [[noreturn]] void Throw(const char* key, const std::string& what) const {
    throw std::invalid_argument(source_ + ": " + section_ + "." + key + " " + what);
  }

 private:
  static std::string Scalar(const YAML::Node& n) {
    return n.IsScalar() ? n.Scalar() : std::string("<non-scalar>");
  }
  YAML::Node node_;
  std::string section_;
  std::string source_;
  std::map<std::string, std::function<void(const YAML::Node&)>> handlers_;
};

// YAML holds the mount's vectors as [x, y, z] in metres or degrees.
struct Vec3 {
  double v[3] = {0, 0, 0};
};


}  // namespace
}  // namespace pitchlab::sensors

namespace YAML {
template <>
struct convert<pitchlab::sensors::Vec3> {
  static bool decode(const Node& node, pitchlab::sensors::Vec3& out) {
    if (!node.IsSequence() || node.size() != 3) return false;
    for (int i = 0; i < 3; ++i) out.v[i] = node[i].as<double>();
    return true;
  }
};
template <>
struct convert<pitchlab::sensors::Lms200RangeMode> {
  static bool decode(const Node& node, pitchlab::sensors::Lms200RangeMode& out) {
    const std::string s = node.as<std::string>();
    if (s == "cm") out = pitchlab::sensors::Lms200RangeMode::kCm;
    else if (s == "mm") out = pitchlab::sensors::Lms200RangeMode::kMm;
    else return false;
    return true;
  }
};
}  // namespace YAML

namespace pitchlab::sensors {

void SensorConfig::Validate() const {
  lms200.Validate();
  pitch_unit.Validate();
  scan.Validate();
  for (double v : {mount.t_base_mount_m.norm(), mount.t_mount_laser_m.norm(),
                   mount.misalignment_rpy_rad.norm()}) {
    if (!std::isfinite(v)) throw std::invalid_argument("mount: offsets must be finite numbers");
  }
}

SensorConfig ParseSensorConfig(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": not valid YAML: " + e.what());
  }
  if (root.IsNull()) return {};
  if (!root.IsMap()) throw std::invalid_argument(source + ": the top level must be a map");
  CheckUniqueYamlKeys(yaml_text, source);

  SensorConfig c;
  auto& l = c.lms200;
  std::uint64_t seed = l.seed;
  SectionReader(root, "lms200", source)
      .Field("fov_deg", l.fov_deg)
      .Field("resolution_deg", l.resolution_deg)
      .Field("range_mode", l.range_mode)
      .Field("noise_sigma_m", l.noise_sigma_m)
      .Field("noise_per_m", l.noise_per_m)
      .Field("incidence_noise_gain", l.incidence_noise_gain)
      .Field("incidence_noise_max_deg", l.incidence_noise_max_deg)
      .Field("range_bias_m", l.range_bias_m)
      .Field("mixed_pixels", l.mixed_pixels)
      .Field("beam_divergence_deg", l.beam_divergence_deg)
      .Field("dropout_grazing_deg", l.dropout_grazing_deg)
      .Field("dropout_grazing_at_90", l.dropout_grazing_at_90)
      .Field("dropout_far_m", l.dropout_far_m)
      .Field("dropout_far_per_m", l.dropout_far_per_m)
      .Field("mount_error_sigma_deg", l.mount_error_sigma_deg)
      .Field("baud", l.baud)
      .Field("seed", seed)
      .Read();
  l.seed = seed;
  auto& p = c.pitch_unit;
  std::uint64_t pitch_seed = p.seed;
  SectionReader(root, "pitch_unit", source)
      .Field("step_deg", p.step_deg)
      .Field("encoder_counts_per_rev", p.encoder_counts_per_rev)
      .Field("min_deg", p.min_deg)
      .Field("max_deg", p.max_deg)
      .Field("max_speed_dps", p.max_speed_dps)
      .Field("settle_s", p.settle_s)
      .Field("line_pitch_error_deg", p.line_pitch_error_deg)
      .Field("line_pitch_error_period_deg", p.line_pitch_error_period_deg)
      .Field("sweep_lag_deg", p.sweep_lag_deg)
      .Field("seed", pitch_seed)
      .Read();
  p.seed = pitch_seed;
  auto& s = c.scan;
  SectionReader(root, "scan", source)
      .Field("pitch_start_deg", s.pitch_start_deg)
      .Field("pitch_end_deg", s.pitch_end_deg)
      .Field("lines", s.lines)
      .Field("line_timeout_ms", s.line_timeout_ms)
      .Read();
  Vec3 base_mount, mount_laser, misalignment_deg;
  for (int i = 0; i < 3; ++i) {
    base_mount.v[i] = c.mount.t_base_mount_m[i];
    mount_laser.v[i] = c.mount.t_mount_laser_m[i];
    misalignment_deg.v[i] = c.mount.misalignment_rpy_rad[i] / kDegToRad;
  }
  SectionReader(root, "mount", source)
      .Field("t_base_mount_m", base_mount)
      .Field("t_mount_laser_m", mount_laser)
      .Field("misalignment_rpy_deg", misalignment_deg)
      .Read();
  for (int i = 0; i < 3; ++i) {
    c.mount.t_base_mount_m[i] = base_mount.v[i];
    c.mount.t_mount_laser_m[i] = mount_laser.v[i];
    c.mount.misalignment_rpy_rad[i] = misalignment_deg.v[i] * kDegToRad;
  }
  try {
    c.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + e.what());
  }
  return c;
}

std::string SensorConfigToYaml(const SensorConfig& c) {
  std::ostringstream os;
  os.precision(17);
  auto vec = [&os](const Eigen::Vector3d& v, double scale) {
    os << "[" << v.x() * scale << ", " << v.y() * scale << ", " << v.z() * scale << "]\n";
  };
  const auto& l = c.lms200;
  os << "lms200:\n"
     << "  fov_deg: " << l.fov_deg << "\n"
     << "  resolution_deg: " << l.resolution_deg << "\n"
     << "  range_mode: " << (l.range_mode == Lms200RangeMode::kCm ? "cm" : "mm") << "\n"
     << "  noise_sigma_m: " << l.noise_sigma_m << "\n"
     << "  noise_per_m: " << l.noise_per_m << "\n"
     << "  incidence_noise_gain: " << l.incidence_noise_gain << "\n"
     << "  incidence_noise_max_deg: " << l.incidence_noise_max_deg << "\n"
     << "  range_bias_m: " << l.range_bias_m << "\n"
     << "  mixed_pixels: " << (l.mixed_pixels ? "true" : "false") << "\n"
     << "  beam_divergence_deg: " << l.beam_divergence_deg << "\n"
     << "  dropout_grazing_deg: " << l.dropout_grazing_deg << "\n"
     << "  dropout_grazing_at_90: " << l.dropout_grazing_at_90 << "\n"
     << "  dropout_far_m: " << l.dropout_far_m << "\n"
     << "  dropout_far_per_m: " << l.dropout_far_per_m << "\n"
     << "  mount_error_sigma_deg: " << l.mount_error_sigma_deg << "\n"
     << "  baud: " << l.baud << "\n"
     << "  seed: " << l.seed << "\n";
  const auto& p = c.pitch_unit;
  os << "pitch_unit:\n"
     << "  step_deg: " << p.step_deg << "\n"
     << "  encoder_counts_per_rev: " << p.encoder_counts_per_rev << "\n"
     << "  min_deg: " << p.min_deg << "\n"
     << "  max_deg: " << p.max_deg << "\n"
     << "  max_speed_dps: " << p.max_speed_dps << "\n"
     << "  settle_s: " << p.settle_s << "\n"
     << "  line_pitch_error_deg: " << p.line_pitch_error_deg << "\n"
     << "  line_pitch_error_period_deg: " << p.line_pitch_error_period_deg << "\n"
     << "  sweep_lag_deg: " << p.sweep_lag_deg << "\n"
     << "  seed: " << p.seed << "\n";
  const auto& s = c.scan;
  os << "scan:\n"
     << "  pitch_start_deg: " << s.pitch_start_deg << "\n"
     << "  pitch_end_deg: " << s.pitch_end_deg << "\n"
     << "  lines: " << s.lines << "\n"
     << "  line_timeout_ms: " << s.line_timeout_ms << "\n";
  os << "mount:\n  t_base_mount_m: ";
  vec(c.mount.t_base_mount_m, 1.0);
  os << "  t_mount_laser_m: ";
  vec(c.mount.t_mount_laser_m, 1.0);
  os << "  misalignment_rpy_deg: ";
  vec(c.mount.misalignment_rpy_rad, 1.0 / kDegToRad);
  return os.str();
}

}  // namespace pitchlab::sensors
