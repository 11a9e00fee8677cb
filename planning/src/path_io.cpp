#include "pitchlab/planning/path_io.hpp"

#include <GeographicLib/LocalCartesian.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "pitchlab/mapping/atomic_file.hpp"

namespace pitchlab::planning {
namespace {

Result<void> WriteText(const std::string& file, const std::string& text) {
  return mapping::WriteFileAtomically(file, text);
}

std::string Num(double v, const char* fmt = "%.4f") {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

// A JSON number, or null where the value is not finite ("%f" of NaN is not JSON).
std::string JsonNum(double v, const char* fmt) { return std::isfinite(v) ? Num(v, fmt) : "null"; }

// A path is written only with finite positions and costs: an empty CSV field or a GeoJSON "[,,]"
// reads as a path to a user's tools when it is the trace of a corrupt map.
Result<void> CheckFinite(const Path& path, const std::string& file) {
  for (std::size_t n = 0; n < path.waypoints.size(); ++n) {
    const Waypoint& w = path.waypoints[n];
    if (!std::isfinite(w.x_m) || !std::isfinite(w.y_m)) {
      return Fail(Error::Code::kInvalidArgument,
                  file + ": waypoint " + std::to_string(n) + " has no finite position (x " +
                      std::to_string(w.x_m) + ", y " + std::to_string(w.y_m) +
                      "): the map's geometry is not finite; nothing written");
    }
  }
  if (!std::isfinite(path.cost) || !std::isfinite(path.length_m)) {
    return Fail(Error::Code::kInvalidArgument,
                file + ": the path's cost or length is not finite; nothing written");
  }
  return {};
}

void Disc(mapping::RgbImage& img, double cx, double cy, double r, std::uint8_t R, std::uint8_t G,
          std::uint8_t B) {
  for (int y = int(cy - r) - 1; y <= int(cy + r) + 1; ++y)
    for (int x = int(cx - r) - 1; x <= int(cx + r) + 1; ++x)
      if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= r) img.Set(x, y, R, G, B);
}

}  // namespace

Result<void> WritePathCsv(const Path& path, const std::string& file) {
  if (Result<void> finite = CheckFinite(path, file); !finite) return finite;
  std::string out = "index,x_m,y_m,z_m,cum_length_m\n";
  double cum = 0;
  for (std::size_t n = 0; n < path.waypoints.size(); ++n) {
    const Waypoint& w = path.waypoints[n];
    if (n > 0) {
      const Waypoint& p = path.waypoints[n - 1];
      const double dz = std::isfinite(w.z_m) && std::isfinite(p.z_m) ? w.z_m - p.z_m : 0.0;
      cum += std::sqrt(std::pow(w.x_m - p.x_m, 2) + std::pow(w.y_m - p.y_m, 2) + dz * dz);
    }
    out += std::to_string(n) + "," + Num(w.x_m) + "," + Num(w.y_m) + "," + Num(w.z_m) + "," +
           Num(cum) + "\n";
  }
  return WriteText(file, out);
}

Result<void> WritePathGeoJson(const Path& path,
                              const std::optional<mapping::GeodeticOrigin>& origin,
                              const std::string& file) {
  if (!origin) {
    return Fail(Error::Code::kInvalidArgument,
                file + ": the map has no geodetic origin, so the path cannot be placed on WGS84");
  }
  if (Result<void> finite = CheckFinite(path, file); !finite) return finite;
  const GeographicLib::LocalCartesian enu(origin->latitude_deg, origin->longitude_deg,
                                          origin->height_m);
  // A position's third value is a height above the ellipsoid (RFC 7946, 3.1.1): a waypoint in a
  // cell of unknown height has none, and one made up (the origin's, as this wrote before) drew a
  // sawtooth in elevation profiles. Heights are given when every waypoint has one, else none.
  const bool heights = std::all_of(path.waypoints.begin(), path.waypoints.end(),
                                   [](const Waypoint& w) { return std::isfinite(w.z_m); });
  std::string coords;
  for (const Waypoint& w : path.waypoints) {
    double lat, lon, h;
    enu.Reverse(w.x_m, w.y_m, heights ? w.z_m : 0.0, lat, lon, h);
    if (!coords.empty()) coords += ",";
    coords += "[" + Num(lon, "%.9f") + "," + Num(lat, "%.9f");
    coords += heights ? "," + Num(h, "%.3f") + "]" : "]";
  }
  const CostParts& c = path.parts;
  std::string props =
      "\"algorithm\":\"" + std::string(ToString(path.algorithm)) + "\"" +
      ",\"cost\":" + JsonNum(path.cost, "%.6f") +
      ",\"cost_roughness\":" + JsonNum(c.roughness, "%.6f") +
      ",\"cost_length\":" + JsonNum(c.length, "%.6f") +
      ",\"cost_inclination_x\":" + JsonNum(c.inclination_x, "%.6f") +
      ",\"cost_inclination_y\":" + JsonNum(c.inclination_y, "%.6f") +
      ",\"cost_unknown\":" + JsonNum(c.unknown, "%.6f") +
      ",\"cost_occupancy\":" + JsonNum(c.occupancy, "%.6f") +
      ",\"length_m\":" + JsonNum(path.length_m, "%.4f") +
      ",\"max_step_m\":" + JsonNum(path.max_step_m, "%.4f") +
      ",\"max_inclination_deg\":" + JsonNum(path.max_inclination_rad * 180 / M_PI, "%.4f") +
      ",\"heights\":" + (heights ? "true" : "false");
  const std::string text =
      "{\"type\":\"FeatureCollection\",\"features\":[{\"type\":\"Feature\",\"properties\":{" +
      props + "},\"geometry\":{\"type\":\"LineString\",\"coordinates\":[" + coords + "]}}]}\n";
  return WriteText(file, text);
}

void DrawPath(const Path& path, const mapping::GridGeometry& g, mapping::RgbImage& img) {
  const double r = std::max(1.0, 0.5 * img.pixels_per_cell);
  for (std::size_t n = 1; n < path.waypoints.size(); ++n) {
    const Eigen::Vector2d a =
        mapping::MapToPixel(g, img, path.waypoints[n - 1].x_m, path.waypoints[n - 1].y_m);
    const Eigen::Vector2d b =
        mapping::MapToPixel(g, img, path.waypoints[n].x_m, path.waypoints[n].y_m);
    const int steps = std::max(1, int(std::ceil((b - a).norm())));
    for (int s = 0; s <= steps; ++s) {
      const Eigen::Vector2d p = a + (b - a) * (double(s) / steps);
      Disc(img, p.x(), p.y(), r, 230, 20, 20);
    }
  }
  if (path.waypoints.empty()) return;
  const Eigen::Vector2d s =
      mapping::MapToPixel(g, img, path.waypoints.front().x_m, path.waypoints.front().y_m);
  const Eigen::Vector2d t =
      mapping::MapToPixel(g, img, path.waypoints.back().x_m, path.waypoints.back().y_m);
  Disc(img, s.x(), s.y(), 3 * r + 2, 20, 200, 20);
  Disc(img, t.x(), t.y(), 3 * r + 2, 20, 60, 230);
}

}  // namespace pitchlab::planning
