#include "report_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "html_report.hpp"
#include "pitchlab/mission/traversability_image.hpp"

// JSON format (all lengths in metres, world frame, z up):
//   cloud:   {origin: [x, y, z], scale, xyz: base64 int16 little-endian triplets}
//            point = origin + (q + 32767) * scale
//   surface: {x0, y0, cell, nx, ny, z0, scale, z: base64 int16 (-32768 unknown), rgb: base64 u8}
//            height = z0 + (q + 32767) * scale
//   true, estimated, stops: [[x, y, z], ...]; start, goal: [x, y, z]
namespace pitchlab::mission {
namespace {

constexpr int kUnknown = -32768;
// Quantisation never finer than 1 mm: the LMS200's range resolution in mm mode.
constexpr double kMinQuantum_m = 0.001;

void PutInt16(std::string& out, int v) {
  const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
  out += static_cast<char>(u & 0xff);
  out += static_cast<char>(u >> 8);
}

// The step that maps [lo, lo + span] onto 65534 levels, not finer than kMinQuantum_m.
double Quantum(double span) { return std::max(span / 65534.0, kMinQuantum_m); }

int Quantise(double v, double lo, double q) {
  return std::clamp(static_cast<int>(std::lround((v - lo) / q)) - 32767, -32767, 32767);
}

nlohmann::json Polyline(const std::vector<Eigen::Vector3d>& points) {
  // A trajectory sample every few centimetres is far more than a line on screen shows; 4000
  // vertices keep a long run's path smooth at full-screen width.
  constexpr std::size_t kMaxVertices = 4000;
  const std::size_t step =
      std::max<std::size_t>(1, (points.size() + kMaxVertices - 1) / kMaxVertices);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < points.size(); k += step) {
    const Eigen::Vector3d& p = points[k];
    out.push_back({std::round(p.x() * 1000) / 1000, std::round(p.y() * 1000) / 1000,
                   std::round(p.z() * 1000) / 1000});
  }
  if (!points.empty() && (points.size() - 1) % step != 0) {
    const Eigen::Vector3d& p = points.back();
    out.push_back({p.x(), p.y(), p.z()});
  }
  return out;
}

nlohmann::json CloudJson(const std::vector<Eigen::Vector3f>& cloud) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Vector3f hi = -lo;
  for (const Eigen::Vector3f& p : cloud) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (cloud.empty()) lo = hi = Eigen::Vector3f::Zero();
  const double q = Quantum((hi - lo).maxCoeff());
  std::string bytes;
  bytes.reserve(cloud.size() * 6);
  for (const Eigen::Vector3f& p : cloud)
    for (int a = 0; a < 3; ++a) PutInt16(bytes, Quantise(p[a], lo[a], q));
  return {{"origin", {lo.x(), lo.y(), lo.z()}}, {"scale", q}, {"xyz", Base64(bytes)}};
}

nlohmann::json SurfaceJson(const SceneSurface& s) {
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float z : s.z_m) {
    if (!std::isfinite(z)) continue;
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  if (!std::isfinite(lo)) lo = hi = 0;
  const double q = Quantum(hi - lo);
  std::string z;
  z.reserve(s.z_m.size() * 2);
  for (float v : s.z_m) PutInt16(z, std::isfinite(v) ? Quantise(v, lo, q) : kUnknown);
  return {
      {"x0", s.x0_m}, {"y0", s.y0_m},   {"cell", s.cell_m},
      {"nx", s.nx},   {"ny", s.ny},     {"z0", lo},
      {"scale", q},   {"z", Base64(z)}, {"rgb", Base64(std::string(s.rgb.begin(), s.rgb.end()))}};
}

nlohmann::json Point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

std::vector<Eigen::Vector3f> DecimateCloud(const mapping::PointCloud& cloud,
                                           std::size_t max_points) {
  const std::size_t k = std::max<std::size_t>(1, (cloud.size() + max_points - 1) / max_points);
  std::vector<Eigen::Vector3f> out;
  out.reserve(cloud.size() / k + 1);
  for (std::size_t n = 0; n < cloud.size(); n += k) out.push_back(cloud[n]);
  return out;
}

SceneSurface BuildSurface(const mapping::ElevationLayers& layers,
                          const planning::TraversabilityGrid& grid, const MapWindow& window) {
  const mapping::GridGeometry& g = layers.geometry;
  const mapping::CellIndex a = g.IndexOf(window.lo_m.x(), window.lo_m.y());
  const mapping::CellIndex b = g.IndexOf(window.hi_m.x(), window.hi_m.y());
  const int i0 = std::max(0, a.i), j0 = std::max(0, a.j);
  const int i1 = std::min(g.size_x - 1, b.i), j1 = std::min(g.size_y - 1, b.j);
  SceneSurface s;
  if (i1 < i0 || j1 < j0) return s;
  const double cells = double(i1 - i0 + 1) * (j1 - j0 + 1);
  const int stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(cells / kSceneMaxCells))));
  s.cell_m = g.cell_m * stride;
  s.nx = (i1 - i0) / stride + 1;
  s.ny = (j1 - j0) / stride + 1;
  s.x0_m = g.x_min_m + i0 * g.cell_m;
  s.y0_m = g.y_min_m + j0 * g.cell_m;
  mapping::ImageOptions one_pixel;
  one_pixel.pixels_per_cell = 1;
  const mapping::RgbImage colours = RenderTraversability(grid, one_pixel);
  s.z_m.resize(static_cast<std::size_t>(s.nx) * s.ny);
  s.rgb.resize(s.z_m.size() * 3);
  for (int v = 0; v < s.ny; ++v) {
    for (int u = 0; u < s.nx; ++u) {
      const int i = i0 + u * stride, j = j0 + v * stride;
      const std::size_t k = g.Linear({i, j}), o = static_cast<std::size_t>(v) * s.nx + u;
      s.z_m[o] = layers.state[k] == mapping::CellState::kObserved ? layers.mean_z[k] : NAN;
      const std::uint8_t* c =
          &colours.rgb[(static_cast<std::size_t>(g.size_y - 1 - j) * colours.width + i) * 3];
      std::copy(c, c + 3, &s.rgb[o * 3]);
    }
  }
  return s;
}

std::string SceneJson(const Scene3D& s) {
  nlohmann::json stops = nlohmann::json::array();
  for (const Eigen::Vector3d& p : s.stops_m) stops.push_back(Point(p));
  return nlohmann::json{{"cloud", CloudJson(s.cloud_m)},
                        {"surface", SurfaceJson(s.surface)},
                        {"true", Polyline(s.true_m)},
                        {"estimated", Polyline(s.estimated_m)},
                        {"stops", stops},
                        {"start", Point(s.start_m)},
                        {"goal", Point(s.goal_m)}}
      .dump();
}

}  // namespace pitchlab::mission
