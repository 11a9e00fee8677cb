#include "pitchlab/worlds/world_metadata.hpp"

#include <mujoco/mujoco.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "number_format.hpp"

namespace pitchlab::worlds {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

std::optional<std::vector<double>> Numeric(const mjModel* model, const char* name) {
  const int id = mj_name2id(model, mjOBJ_NUMERIC, name);
  if (id < 0) return std::nullopt;
  const double* data = model->numeric_data + model->numeric_adr[id];
  return std::vector<double>(data, data + model->numeric_size[id]);
}

[[noreturn]] void Bad(const char* field, const std::vector<double>& values, const char* want) {
  std::ostringstream message;
  message << "world custom field '" << field << "' = [";
  for (size_t i = 0; i < values.size(); ++i) message << (i ? " " : "") << values[i];
  message << "]: expected " << want;
  throw std::invalid_argument(message.str());
}

std::string EscapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\n':
        out += ' ';
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

WorldMetadata ReadWorldMetadata(const mjModel* model) {
  if (model == nullptr) throw std::invalid_argument("ReadWorldMetadata: model is null");
  WorldMetadata metadata;
  const int text_id = mj_name2id(model, mjOBJ_TEXT, kDescriptionField);
  if (text_id >= 0) metadata.description = model->text_data + model->text_adr[text_id];

  if (const auto origin = Numeric(model, kGeodeticOriginField)) {
    const auto& v = *origin;
    if (v.size() != 3 || std::abs(v[0]) > 90.0 || std::abs(v[1]) > 180.0) {
      Bad(kGeodeticOriginField, v, "3 values: lat_deg in [-90, 90], lon_deg in [-180, 180], h_m");
    }
    metadata.geodetic_origin = GeodeticPoint{v[0], v[1], v[2]};
  }
  if (const auto bounds = Numeric(model, kBoundsField)) {
    const auto& v = *bounds;
    if (v.size() != 4 || !(v[0] < v[2]) || !(v[1] < v[3])) {
      Bad(kBoundsField, v, "4 values: xmin ymin xmax ymax with xmin < xmax, ymin < ymax");
    }
    metadata.bounds = Bounds2d{v[0], v[1], v[2], v[3]};
  } else {
    // Any MJCF is a world: fall back to the square MuJoCo's statistics say the model spans.
    const double c_x = model->stat.center[0], c_y = model->stat.center[1];
    const double r = model->stat.extent;
    metadata.bounds = Bounds2d{c_x - r, c_y - r, c_x + r, c_y + r};
  }
  if (const auto start = Numeric(model, kDefaultStartField)) {
    const auto& v = *start;
    if (v.size() != 3) Bad(kDefaultStartField, v, "3 values: x_m y_m yaw_deg");
    metadata.default_start = StartPose{v[0], v[1], v[2] * kDegToRad};
  }
  if (const auto goal = Numeric(model, kDefaultGoalField)) {
    const auto& v = *goal;
    if (v.size() != 2) Bad(kDefaultGoalField, v, "2 values: x_m y_m");
    metadata.default_goal = GoalPoint{v[0], v[1]};
  }
  return metadata;
}

std::string FormatMetadataMjcf(const WorldMetadata& metadata) {
  const auto& b = metadata.bounds;
  const auto& s = metadata.default_start;
  std::ostringstream out;
  out << "  <custom>\n";
  // MuJoCo rejects empty text fields, and the reader's defaults stand in for absent ones.
  if (!metadata.description.empty()) {
    out << "    <text name=\"" << kDescriptionField << "\" data=\""
        << EscapeXml(metadata.description) << "\"/>\n";
  }
  if (metadata.geodetic_origin) {
    const auto& g = *metadata.geodetic_origin;
    out << "    <numeric name=\"" << kGeodeticOriginField << "\" data=\""
        << FormatFixed(g.latitude_deg, 9) << " " << FormatFixed(g.longitude_deg, 9) << " "
        << FormatFixed(g.height_m, 4) << "\"/>\n";
  }
  if (b.x_min_m < b.x_max_m && b.y_min_m < b.y_max_m) {
    out << "    <numeric name=\"" << kBoundsField << "\" data=\"" << FormatFixed(b.x_min_m, 4)
        << " " << FormatFixed(b.y_min_m, 4) << " " << FormatFixed(b.x_max_m, 4) << " "
        << FormatFixed(b.y_max_m, 4) << "\"/>\n";
  }
  out << "    <numeric name=\"" << kDefaultStartField << "\" data=\"" << FormatFixed(s.x_m, 4)
      << " " << FormatFixed(s.y_m, 4) << " " << FormatFixed(s.yaw_rad / kDegToRad, 3) << "\"/>\n";
  if (metadata.default_goal) {
    out << "    <numeric name=\"" << kDefaultGoalField << "\" data=\""
        << FormatFixed(metadata.default_goal->x_m, 4) << " "
        << FormatFixed(metadata.default_goal->y_m, 4) << "\"/>\n";
  }
  out << "  </custom>\n";
  return out.str();
}

}  // namespace pitchlab::worlds
