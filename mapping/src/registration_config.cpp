#include "pitchlab/mapping/registration_config.hpp"
#include "pitchlab/sensors/yaml_keys.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include <yaml-cpp/yaml.h>

namespace pitchlab::mapping {
namespace {

constexpr char kSection[] = "registration";

[[noreturn]] void Throw(const std::string& source, const std::string& key,
                        const std::string& what) {
  throw std::invalid_argument(source + ": " + kSection + "." + key + " " + what);
}

std::string BackendName(RegistrationBackend b) {
  return b == RegistrationBackend::kPcl ? "pcl" : "fast";
}

std::string FeatureName(FeatureKind f) {
  switch (f) {
    case FeatureKind::kFpfh:
      return "fpfh";
    case FeatureKind::kNarf:
      return "narf";
    case FeatureKind::kNone:
      return "none";
  }
  return "?";
}

// The settings that may be `auto` (kAuto).
bool MayBeAuto(const std::string& key) {
  return key == "length_scale" || key == "inlier_distance_m" || key == "max_rmse_m" ||
         key == "free_space_margin_m";
}

// One handler per key; visits every field of the config (so reading and writing cannot diverge).
template <typename Visitor>
void VisitFields(RegistrationConfig& c, Visitor&& v) {
  v("length_scale", c.length_scale);
  v("icp_voxel_m", c.icp_voxel_m);
  v("feature_voxel_m", c.feature_voxel_m);
  v("normal_radius_m", c.normal_radius_m);
  v("icp_normal_radius_m", c.icp_normal_radius_m);
  v("feature_radius_m", c.feature_radius_m);
  v("max_neighbors", c.max_neighbors);
  v("max_feature_points", c.max_feature_points);
  v("narf_angular_resolution_deg", c.narf_angular_resolution_deg);
  v("narf_noise_level_m", c.narf_noise_level_m);
  v("narf_support_m", c.narf_support_m);
  v("sac_iterations", c.sac_iterations);
  v("sac_inlier_m", c.sac_inlier_m);
  v("sac_edge_similarity", c.sac_edge_similarity);
  v("sac_min_inliers", c.sac_min_inliers);
  v("sac_hypotheses", c.sac_hypotheses);
  v("degeneracy_ratio", c.degeneracy_ratio);
  v("guess_degeneracy_ratio", c.guess_degeneracy_ratio);
  v("free_ratio", c.free_ratio);
  v("degeneracy_probe_m", c.degeneracy_probe_m);
  v("degeneracy_probe_deg", c.degeneracy_probe_deg);
  v("degeneracy_search_m", c.degeneracy_search_m);
  v("guess_search_m", c.guess_search_m);
  v("guess_search_deg", c.guess_search_deg);
  v("carry_max_m", c.carry_max_m);
  v("carry_max_deg", c.carry_max_deg);
  v("icp_max_iterations", c.icp_max_iterations);
  v("icp_epsilon", c.icp_epsilon);
  v("icp_max_distance_m", c.icp_max_distance_m);
  v("icp_min_distance_m", c.icp_min_distance_m);
  v("icp_max_points", c.icp_max_points);
  v("confined_scene_voxels", c.confined_scene_voxels);
  v("constraint_translation_m", c.constraint_translation_m);
  v("constraint_rotation_deg", c.constraint_rotation_deg);
  v("constant_velocity_fallback", c.constant_velocity_fallback);
  v("inlier_distance_m", c.inlier_distance_m);
  v("min_inlier_ratio", c.min_inlier_ratio);
  v("max_rmse_m", c.max_rmse_m);
  v("free_space_margin_m", c.free_space_margin_m);
}

// The length settings (metres), all multiplied by length_scale.
template <typename Visitor>
void VisitLengths(RegistrationConfig& c, Visitor&& v) {
  for (double* length :
       {&c.icp_voxel_m, &c.feature_voxel_m, &c.normal_radius_m, &c.icp_normal_radius_m,
        &c.feature_radius_m, &c.narf_noise_level_m, &c.narf_support_m, &c.sac_inlier_m,
        &c.degeneracy_probe_m, &c.degeneracy_search_m, &c.guess_search_m, &c.carry_max_m,
        &c.icp_max_distance_m, &c.icp_min_distance_m, &c.constraint_translation_m,
        &c.inlier_distance_m, &c.max_rmse_m, &c.free_space_margin_m}) {
    v(*length);
  }
}

// The data the defaults were set on (see RegistrationConfig::length_scale): their noise as
// MeasureCloud measures it [m] and their median range [m], each the geometric middle of what
// simulated and real LMS scans measure.
constexpr double kReferenceNoise_m = 0.0034;
constexpr double kReferenceRange_m = 2.0;
// Noise below this fraction of the median range is a float's rounding, not a sensor's: synthetic.
constexpr double kNoiseFloor = 1e-4;

double Decade(double ratio) { return std::pow(10.0, std::round(std::log10(ratio))); }

void ReadEnums(const std::string& key, const YAML::Node& n, RegistrationConfig& c,
               const std::string& source) {
  const std::string s = n.IsScalar() ? n.Scalar() : "<non-scalar>";
  if (key == "backend") {
    if (s == "fast")
      c.backend = RegistrationBackend::kFast;
    else if (s == "pcl")
      c.backend = RegistrationBackend::kPcl;
    else
      Throw(source, key, "must be fast or pcl ('" + s + "')");
  } else {
    if (s == "fpfh")
      c.features = FeatureKind::kFpfh;
    else if (s == "narf")
      c.features = FeatureKind::kNarf;
    else if (s == "none")
      c.features = FeatureKind::kNone;
    else
      Throw(source, key, "must be fpfh, narf or none ('" + s + "')");
  }
}

}  // namespace

void RegistrationConfig::Validate() const {
  auto require = [](bool ok, const char* field, double value, const char* what) {
    if (!ok) {
      std::ostringstream os;
      os << "registration." << field << " = " << value << ": " << what;
      throw std::invalid_argument(os.str());
    }
  };
  auto positive_or_auto = [&](double v, const char* field) {
    require(std::isnan(v) || (v > 0 && std::isfinite(v)), field, v, "must be > 0 or auto");
  };
  positive_or_auto(length_scale, "length_scale");
  positive_or_auto(inlier_distance_m, "inlier_distance_m");
  positive_or_auto(max_rmse_m, "max_rmse_m");
  positive_or_auto(free_space_margin_m, "free_space_margin_m");
  require(icp_voxel_m > 0, "icp_voxel_m", icp_voxel_m, "must be > 0");
  require(feature_voxel_m > 0, "feature_voxel_m", feature_voxel_m, "must be > 0");
  require(normal_radius_m > 0, "normal_radius_m", normal_radius_m, "must be > 0");
  require(icp_normal_radius_m > 0, "icp_normal_radius_m", icp_normal_radius_m, "must be > 0");
  require(feature_radius_m > normal_radius_m * 0.5, "feature_radius_m", feature_radius_m,
          "must exceed half the normal radius");
  require(max_neighbors >= 5, "max_neighbors", max_neighbors, "must be >= 5");
  require(max_feature_points >= 10, "max_feature_points", max_feature_points, "must be >= 10");
  require(narf_angular_resolution_deg > 0 && narf_angular_resolution_deg <= 10,
          "narf_angular_resolution_deg", narf_angular_resolution_deg, "must be in (0, 10]");
  require(narf_noise_level_m >= 0, "narf_noise_level_m", narf_noise_level_m, "must be >= 0");
  require(narf_support_m > 0, "narf_support_m", narf_support_m, "must be > 0");
  require(sac_iterations >= 1, "sac_iterations", sac_iterations, "must be >= 1");
  require(sac_inlier_m > 0, "sac_inlier_m", sac_inlier_m, "must be > 0");
  require(sac_edge_similarity > 0 && sac_edge_similarity < 1, "sac_edge_similarity",
          sac_edge_similarity, "must be in (0, 1)");
  require(sac_min_inliers >= 3, "sac_min_inliers", sac_min_inliers, "must be >= 3");
  require(sac_hypotheses >= 1 && sac_hypotheses <= 16, "sac_hypotheses", sac_hypotheses,
          "must be in [1, 16]");
  require(degeneracy_ratio >= 0 && degeneracy_ratio < 1, "degeneracy_ratio", degeneracy_ratio,
          "must be in [0, 1)");
  require(guess_degeneracy_ratio >= 0 && guess_degeneracy_ratio < 1, "guess_degeneracy_ratio",
          guess_degeneracy_ratio, "must be in [0, 1)");
  require(free_ratio >= 0 && free_ratio <= degeneracy_ratio, "free_ratio", free_ratio,
          "must be in [0, degeneracy_ratio]");
  require(degeneracy_probe_m > 0, "degeneracy_probe_m", degeneracy_probe_m, "must be > 0");
  require(degeneracy_probe_deg > 0 && degeneracy_probe_deg < 90, "degeneracy_probe_deg",
          degeneracy_probe_deg, "must be in (0, 90)");
  require(degeneracy_search_m >= 0, "degeneracy_search_m", degeneracy_search_m, "must be >= 0");
  require(guess_search_m >= 0, "guess_search_m", guess_search_m, "must be >= 0");
  require(guess_search_deg >= 0 && guess_search_deg < 90, "guess_search_deg", guess_search_deg,
          "must be in [0, 90)");
  require(carry_max_m >= 0, "carry_max_m", carry_max_m, "must be >= 0");
  require(carry_max_deg >= 0, "carry_max_deg", carry_max_deg, "must be >= 0");
  require(icp_max_iterations >= 1, "icp_max_iterations", icp_max_iterations, "must be >= 1");
  require(icp_epsilon > 0, "icp_epsilon", icp_epsilon, "must be > 0");
  require(icp_max_distance_m > 0, "icp_max_distance_m", icp_max_distance_m, "must be > 0");
  require(icp_min_distance_m > 0 && icp_min_distance_m <= icp_max_distance_m, "icp_min_distance_m",
          icp_min_distance_m, "must be in (0, icp_max_distance_m]");
  require(icp_max_points >= 50, "icp_max_points", icp_max_points, "must be >= 50");
  require(confined_scene_voxels >= 0, "confined_scene_voxels", confined_scene_voxels,
          "must be >= 0");
  require(constraint_translation_m > 0, "constraint_translation_m", constraint_translation_m,
          "must be > 0");
  require(constraint_rotation_deg > 0 && constraint_rotation_deg <= 180, "constraint_rotation_deg",
          constraint_rotation_deg, "must be in (0, 180]");
  require(min_inlier_ratio >= 0 && min_inlier_ratio <= 1, "min_inlier_ratio", min_inlier_ratio,
          "must be in [0, 1]");
}

RegistrationConfig RegistrationConfig::Resolve(const CloudStatistics& source,
                                               const CloudStatistics& target) const {
  RegistrationConfig r = *this;
  if (std::isnan(r.length_scale)) {
    if (source.noise_m > kNoiseFloor * source.median_range_m) {
      r.length_scale = Decade(std::sqrt(source.noise_m / kReferenceNoise_m *
                                        source.median_range_m / kReferenceRange_m));
    } else if (source.median_range_m > 0) {
      r.length_scale = Decade(source.median_range_m / kReferenceRange_m);
    } else {
      r.length_scale = 1.0;
    }
  }
  VisitLengths(r, [&](double& length) {
    if (!std::isnan(length)) length *= r.length_scale;
  });
  const double noise = std::hypot(source.noise_m, target.noise_m);
  if (std::isnan(r.inlier_distance_m)) r.inlier_distance_m = std::max(r.icp_voxel_m, 3 * noise);
  if (std::isnan(r.max_rmse_m)) r.max_rmse_m = r.inlier_distance_m / std::sqrt(3.0);
  if (std::isnan(r.free_space_margin_m)) {
    r.free_space_margin_m = std::max(0.1 * r.length_scale, 3 * noise);
  }
  return r;
}

RegistrationConfig ParseRegistrationConfig(const std::string& yaml_text,
                                           const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": not YAML: " + e.what());
  }
  sensors::CheckUniqueYamlKeys(yaml_text, source);
  RegistrationConfig config;
  const YAML::Node node = root.IsMap() ? root[kSection] : YAML::Node();
  if (!node) return config;
  if (!node.IsMap()) throw std::invalid_argument(source + ": '" + kSection + "' must be a map");

  std::map<std::string, std::function<void(const YAML::Node&)>> handlers;
  VisitFields(config, [&](const char* key, auto& field) {
    handlers[key] = [&field, key, &source](const YAML::Node& n) {
      using Field = std::decay_t<decltype(field)>;
      if constexpr (std::is_same_v<Field, double>) {
        if (n.IsScalar() && n.Scalar() == "auto") {
          if (!MayBeAuto(key)) Throw(source, key, "cannot be auto");
          field = kAuto;
          return;
        }
      }
      try {
        field = n.as<Field>();
      } catch (const YAML::Exception&) {
        Throw(source, key,
              "has the wrong type ('" + (n.IsScalar() ? n.Scalar() : "<non-scalar>") + "')");
      }
    };
  });
  for (const char* key : {"backend", "features"}) {
    handlers[key] = [&config, key, &source](const YAML::Node& n) {
      ReadEnums(key, n, config, source);
    };
  }
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    auto it = handlers.find(key);
    if (it == handlers.end()) Throw(source, key, "is not a known setting");
    it->second(kv.second);
  }
  try {
    config.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + e.what());
  }
  return config;
}

RegistrationConfig LoadRegistrationConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  return ParseRegistrationConfig(text.str(), path);
}

std::string RegistrationConfigToYaml(const RegistrationConfig& config) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << kSection << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "backend" << YAML::Value << BackendName(config.backend);
  out << YAML::Key << "features" << YAML::Value << FeatureName(config.features);
  RegistrationConfig copy = config;
  VisitFields(copy, [&](const char* key, auto& field) {
    out << YAML::Key << key << YAML::Value;
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, double>) {
      if (std::isnan(field)) {
        out << "auto";
        return;
      }
    }
    out << field;
  });
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace pitchlab::mapping
