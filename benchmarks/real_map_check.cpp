#include "real_map_check.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::benchmarks {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kCell_m = 0.1;        // `pitchlab map`'s default cell
constexpr double kFlat_m = 0.02;       // the "floor within +-2 cm of one plane"
// A cell belongs to the floor when it lies within the P3-AT's climbable step (datasheet 8.9 cm)
// of the level floor under the first sensor: what the robot treats as one level.
const double kFloorBand_m = planning::RobotLimits::P3AT().step_max_m;

// Least-squares plane z = a x + b y + c through the floor cells; its tilt, RMS and share within
// kFlat_m, also by distance from `from` (where a scan's angle errors grow with range).
nlohmann::json FloorPlane(const std::vector<Eigen::Vector3d>& cells, const Eigen::Vector2d& from) {
  if (cells.size() < 3) return {{"cells", cells.size()}};
  Eigen::MatrixXd A(cells.size(), 3);
  Eigen::VectorXd z(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) {
    A.row(k) << cells[k].x(), cells[k].y(), 1.0;
    z(k) = cells[k].z();
  }
  const Eigen::Vector3d p = A.colPivHouseholderQr().solve(z);
  const Eigen::VectorXd r = z - A * p;
  const double within =
      static_cast<double>((r.array().abs() <= kFlat_m).count()) / static_cast<double>(r.size());
  nlohmann::json bands = nlohmann::json::array();
  const double edges[] = {0, 2, 4, 8, 16, 1e9};
  for (int b = 0; b + 1 < 6; ++b) {
    std::size_t n = 0, flat = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const double d = (cells[k].head<2>() - from).norm();
      if (d < edges[b] || d >= edges[b + 1]) continue;
      ++n;
      flat += std::abs(r(k)) <= kFlat_m;
    }
    if (n == 0) continue;
    bands.push_back({{"from_m", edges[b]},
                     {"to_m", edges[b + 1] < 1e8 ? nlohmann::json(edges[b + 1]) : nlohmann::json()},
                     {"cells", n},
                     {"within_2cm", static_cast<double>(flat) / static_cast<double>(n)}});
  }
  return {{"cells", cells.size()},
          {"tilt_deg", std::atan(std::hypot(p(0), p(1))) * 180 / kPi},
          {"rms_m", std::sqrt(r.squaredNorm() / static_cast<double>(r.size()))},
          {"within_2cm", within},
          {"by_distance", bands}};
}

// The farthest along `axis` (from `from`) of the floor cells (`floor`, by linear index) reachable
// from `from` through allowed moves [m]: with unknown cells enterable a search may wander off
// the seen floor, and only the seen floor counts as plannable (a free cell 33 m away on a shelf
// is no corridor).
double ReachAlong(const planning::TraversabilityGrid& grid, const std::vector<char>& floor,
                  const Eigen::Vector2d& from, const Eigen::Vector2d& axis) {
  const std::vector<bool> reached = planning::ReachableCells(grid, from);
  double farthest = 0;
  for (std::size_t k = 0; k < reached.size(); ++k) {
    if (!reached[k] || !floor[k] || grid.blocked[k] != planning::Blocked::kFree) continue;
    farthest =
        std::max(farthest, (grid.geometry.CenterOf(grid.geometry.FromLinear(k)) - from).dot(axis));
  }
  return farthest;
}

}  // namespace

nlohmann::json CheckMap(const std::vector<PosedCloud>& scans) {
  if (scans.empty()) throw std::runtime_error("map check: no scans");
  // The scans in the map frame, levelled by the first one's floor.
  std::vector<mapping::PointCloud> clouds;
  std::vector<Eigen::Vector3f> sensors;
  for (const PosedCloud& s : scans) {
    const Eigen::Isometry3f T = s.T_map_scan.cast<float>();
    mapping::PointCloud c;
    c.reserve(s.points->size());
    for (const Eigen::Vector3f& p : *s.points) c.push_back(T * p);
    clouds.push_back(std::move(c));
    sensors.push_back(T * s.sensor);
  }
  Result<mapping::GroundLevel> level = mapping::FitGroundLevel(clouds.front(), sensors.front());
  if (!level) throw std::runtime_error("map check: " + level.error().message);
  const Eigen::Matrix3f R = level->R_level.cast<float>();
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    for (Eigen::Vector3f& p : clouds[k]) {
      p = R * p;
      lo = lo.cwiseMin(p.head<2>().cast<double>());
      hi = hi.cwiseMax(p.head<2>().cast<double>());
    }
    sensors[k] = R * sensors[k];
  }
  mapping::InsertConfig insert;
  insert.sensor_height_m = level->sensor_height_m;
  mapping::ElevationMap map(mapping::GridGeometry::Covering(lo, hi, kCell_m, 0.5), std::nullopt);
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    map.InsertScan(clouds[k].data(), clouds[k].size(), sensors[k], insert);
  }
  const mapping::ElevationLayers layers = mapping::ComputeLayers(map);
  const mapping::GridGeometry& g = map.geometry();

  // The floor, and its extent along the line the scans were taken on.
  const double floor_z = sensors.front().z() - level->sensor_height_m;
  const Eigen::Vector2d from = sensors.front().head<2>().cast<double>();
  Eigen::Vector2d axis = sensors.back().head<2>().cast<double>() - from;
  axis = axis.norm() > 1e-6 ? axis.normalized() : Eigen::Vector2d::UnitX();
  std::vector<Eigen::Vector3d> floor;
  std::vector<char> is_floor(g.cell_count(), 0);
  double seen_m = 0;
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    if (layers.state[k] != mapping::CellState::kObserved) continue;
    const double z = layers.mean_z[k];
    if (!(std::abs(z - floor_z) <= kFloorBand_m)) continue;
    const Eigen::Vector2d c = g.CenterOf(g.FromLinear(k));
    floor.emplace_back(c.x(), c.y(), z);
    is_floor[k] = 1;
    seen_m = std::max(seen_m, (c - from).dot(axis));
  }
  nlohmann::json reach;
  for (const auto& [policy, name] : {std::pair{planning::UnknownPolicy::kForbid, "forbid"},
                                     {planning::UnknownPolicy::kPenalise, "penalise"}}) {
    planning::PlannerConfig config;
    config.unknown = policy;
    const planning::TraversabilityGrid grid = planning::BuildTraversability(layers, config);
    reach[name] = ReachAlong(grid, is_floor, from, axis);
  }
  return {{"levelling",
           {{"tilt_removed_deg", level->tilt_rad * 180 / kPi},
            {"residual_m", level->residual_m},
            {"sensor_height_m", level->sensor_height_m}}},
          {"floor", FloorPlane(floor, from)},
          {"floor_seen_along_m", seen_m},
          {"reachable_along_m", reach}};
}

}  // namespace pitchlab::benchmarks
