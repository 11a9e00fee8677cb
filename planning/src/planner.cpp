#include "pitchlab/planning/planner.hpp"

#include <algorithm>
#include <cmath>
#include <queue>
#include <sstream>
#include <stdexcept>

namespace pitchlab::planning {
namespace {

using mapping::CellIndex;
using mapping::GridGeometry;

struct Offset {
  int di, dj;
  double unit;  // 2D length in cells
};
// Orthogonal first, then diagonal: the order ListEdges and the searches share.
constexpr Offset kNeighbours[8] = {{1, 0, 1.0},      {-1, 0, 1.0},     {0, 1, 1.0},
                                   {0, -1, 1.0},     {1, 1, M_SQRT2},  {1, -1, M_SQRT2},
                                   {-1, 1, M_SQRT2}, {-1, -1, M_SQRT2}};

// Eq. 4 and 5 for the edge a -> b of 2D length d_m, whether allowed or not.
inline double RawEdgeCost(const TraversabilityGrid& T, std::size_t a, std::size_t b, double d_m,
                          CostParts* parts) {
  const float za = T.z_m[a], zb = T.z_m[b];
  const double dz = (std::isfinite(za) && std::isfinite(zb)) ? double(zb) - za : 0.0;
  const double p = std::sqrt(d_m * d_m + dz * dz);                    // Eq. 4: 3D Euclidean length
  const double cost = T.enter_cost[b] + T.config.weights.length * p;  // Eq. 5
  if (parts) {
    const CostWeights& w = T.config.weights;
    const bool unknown = !std::isfinite(zb);
    parts->length += w.length * p;
    if (unknown) {
      parts->unknown += T.enter_cost[b];
    } else {
      parts->roughness += w.roughness * T.roughness_m[b];
      parts->inclination_x += w.inclination_x * std::abs(T.phi_x_rad[b]);
      parts->inclination_y += w.inclination_y * std::abs(T.phi_y_rad[b]);
    }
  }
  return cost;
}

// Edge rule: the target is free and a diagonal does not cut a blocked corner.
inline bool Allowed(const TraversabilityGrid& T, const CellIndex& a, const Offset& o) {
  const int b = static_cast<int>(&o - kNeighbours);
  return T.moves[T.geometry.Linear(a)] >> b & 1;
}

std::string Where(const Eigen::Vector2d& p) {
  std::ostringstream os;
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

double TiltOf(const TraversabilityGrid& T, std::size_t k) {
  const double tx = std::tan(T.phi_x_rad[k]), ty = std::tan(T.phi_y_rad[k]);
  return std::atan(std::sqrt(tx * tx + ty * ty));
}

Path Reconstruct(const TraversabilityGrid& T, const std::vector<std::int32_t>& parent,
                 std::size_t start, std::size_t goal, double cost) {
  const GridGeometry& g = T.geometry;
  Path path;
  path.cost = cost;
  std::vector<std::size_t> ks;
  for (std::size_t k = goal; k != start; k = static_cast<std::size_t>(parent[k])) ks.push_back(k);
  ks.push_back(start);
  std::reverse(ks.begin(), ks.end());
  for (std::size_t n = 0; n < ks.size(); ++n) {
    const CellIndex c = g.FromLinear(ks[n]);
    const Eigen::Vector2d xy = g.CenterOf(c);
    path.cells.push_back(c);
    path.waypoints.push_back({xy.x(), xy.y(), T.z_m[ks[n]]});
    if (std::isfinite(T.z_m[ks[n]]))
      path.max_inclination_rad = std::max(path.max_inclination_rad, TiltOf(T, ks[n]));
    if (n == 0) continue;
    const CellIndex p = g.FromLinear(ks[n - 1]);
    const double d = std::hypot(c.i - p.i, c.j - p.j) * g.cell_m;
    CostParts before = path.parts;
    RawEdgeCost(T, ks[n - 1], ks[n], d, &path.parts);
    path.length_m += (path.parts.length - before.length) / T.config.weights.length;
    const float za = T.z_m[ks[n - 1]], zb = T.z_m[ks[n]];
    if (std::isfinite(za) && std::isfinite(zb))
      path.max_step_m = std::max(path.max_step_m, std::abs(double(zb) - za));
  }
  return path;
}

}  // namespace

Algorithm ParseAlgorithm(const std::string& name) {
  if (name == "dijkstra") return Algorithm::kDijkstra;
  if (name == "astar" || name == "a*") return Algorithm::kAStar;
  throw std::invalid_argument("unknown algorithm '" + name + "'; known: dijkstra, astar");
}

const char* ToString(Algorithm a) { return a == Algorithm::kAStar ? "astar" : "dijkstra"; }

const char* ToString(NoPath::Reason r) {
  switch (r) {
    case NoPath::Reason::kStartOutsideMap:
      return "start_outside_map";
    case NoPath::Reason::kGoalOutsideMap:
      return "goal_outside_map";
    case NoPath::Reason::kStartBlocked:
      return "start_blocked";
    case NoPath::Reason::kGoalBlocked:
      return "goal_blocked";
    case NoPath::Reason::kDisconnected:
      return "disconnected";
  }
  return "?";
}

tl::expected<Path, NoPath> PlanPath(const TraversabilityGrid& T, const Eigen::Vector2d& start_m,
                                    const Eigen::Vector2d& goal_m, Algorithm algorithm) {
  const GridGeometry& g = T.geometry;
  const auto fail = [](NoPath::Reason r, std::string msg) {
    return tl::make_unexpected(NoPath{r, std::move(msg)});
  };
  const CellIndex s = g.IndexOf(start_m.x(), start_m.y()), t = g.IndexOf(goal_m.x(), goal_m.y());
  if (!g.Contains(s))
    return fail(NoPath::Reason::kStartOutsideMap,
                "start " + Where(start_m) + " is outside the map");
  if (!g.Contains(t))
    return fail(NoPath::Reason::kGoalOutsideMap, "goal " + Where(goal_m) + " is outside the map");
  const std::size_t ks = g.Linear(s), kt = g.Linear(t);
  if (!T.Free(ks) && T.blocked[ks] != Blocked::kUnknown)
    return fail(NoPath::Reason::kStartBlocked,
                "start " + Where(start_m) + " is blocked: " + ToString(T.blocked[ks]));
  if (!T.Free(kt))
    return fail(NoPath::Reason::kGoalBlocked,
                "goal " + Where(goal_m) + " is blocked: " + ToString(T.blocked[kt]));

  const bool astar = algorithm == Algorithm::kAStar;
  const double w_len = T.config.weights.length * g.cell_m, c_min = T.min_enter_cost;
  const auto heuristic = [&](const CellIndex& c) {
    if (!astar) return 0.0;
    const int dx = std::abs(c.i - t.i), dy = std::abs(c.j - t.j);
    const int lo = std::min(dx, dy), hi = std::max(dx, dy);
    // Octile distance times W_P (P >= 2D length) plus the cheapest entry cost per step: a lower
    // bound of every remaining edge's cost, and consistent.
    return w_len * ((hi - lo) + M_SQRT2 * lo) + c_min * hi;
  };
  std::vector<double> dist(g.cell_count(), std::numeric_limits<double>::infinity());
  std::vector<std::int32_t> parent(g.cell_count(), -1);
  std::vector<std::uint8_t> closed(g.cell_count(), 0);
  using Entry = std::pair<double, std::uint32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  dist[ks] = 0.0;
  open.emplace(heuristic(s), static_cast<std::uint32_t>(ks));
  std::size_t expanded = 0;
  const double w_p = T.config.weights.length;
  double step_m[8];
  for (int b = 0; b < 8; ++b) step_m[b] = kNeighbours[b].unit * g.cell_m;
  while (!open.empty()) {
    const std::uint32_t k = open.top().second;
    open.pop();
    if (closed[k]) continue;
    closed[k] = 1;
    ++expanded;
    if (k == kt) break;
    const CellIndex c = g.FromLinear(k);
    const std::uint8_t moves = T.moves[k];
    const float zk = T.z_m[k];
    for (int b = 0; b < 8; ++b) {
      if (!(moves >> b & 1)) continue;
      const Offset& o = kNeighbours[b];
      const std::size_t kn = k + o.di + static_cast<std::ptrdiff_t>(o.dj) * g.size_x;
      if (closed[kn]) continue;
      const float zn = T.z_m[kn];
      const double dz = (std::isfinite(zk) && std::isfinite(zn)) ? double(zn) - zk : 0.0;
      const double d = step_m[b];
      const double edge = T.enter_cost[kn] + w_p * std::sqrt(d * d + dz * dz);  // Eq. 4-5
      const double nd = dist[k] + edge;
      if (nd < dist[kn]) {
        dist[kn] = nd;
        parent[kn] = static_cast<std::int32_t>(k);
        open.emplace(nd + heuristic(CellIndex{c.i + o.di, c.j + o.dj}),
                     static_cast<std::uint32_t>(kn));
      }
    }
  }
  if (!closed[kt]) {
    return fail(NoPath::Reason::kDisconnected,
                "no path from " + Where(start_m) + " to " + Where(goal_m) +
                    ": the goal is not connected to the start through cells the robot may enter");
  }
  Path path = Reconstruct(T, parent, ks, kt, dist[kt]);
  path.algorithm = algorithm;
  path.expanded = expanded;
  return path;
}

double EdgeCost(const TraversabilityGrid& T, std::size_t a, std::size_t b, CostParts* parts) {
  const GridGeometry& g = T.geometry;
  const CellIndex ca = g.FromLinear(a), cb = g.FromLinear(b);
  for (const Offset& o : kNeighbours) {
    if (ca.i + o.di != cb.i || ca.j + o.dj != cb.j) continue;
    if (!Allowed(T, ca, o)) return std::nan("");
    return RawEdgeCost(T, a, b, o.unit * g.cell_m, parts);
  }
  return std::nan("");
}

std::vector<GraphEdge> ListEdges(const TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  std::vector<GraphEdge> edges;
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    if (!T.Free(k)) continue;
    const CellIndex c = g.FromLinear(k);
    for (const Offset& o : kNeighbours) {
      if (!Allowed(T, c, o)) continue;
      const std::size_t kn = g.Linear({c.i + o.di, c.j + o.dj});
      edges.push_back({static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(kn),
                       RawEdgeCost(T, k, kn, o.unit * g.cell_m, nullptr)});
    }
  }
  return edges;
}

PathOnMap EvaluatePath(const TraversabilityGrid& T, const Path& path) {
  const GridGeometry& g = T.geometry;
  PathOnMap out;
  for (std::size_t n = 0; n < path.cells.size(); ++n) {
    const CellIndex c = path.cells[n];
    if (!g.Contains(c)) throw std::invalid_argument("evaluate path: a path cell is off the grid");
    const std::size_t k = g.Linear(c);
    if (n == 0) continue;
    out.forbidden_cells += !T.Free(k);
    out.unknown_cells += !std::isfinite(T.z_m[k]);
    const CellIndex p = path.cells[n - 1];
    out.cost +=
        RawEdgeCost(T, g.Linear(p), k, std::hypot(c.i - p.i, c.j - p.j) * g.cell_m, nullptr);
  }
  return out;
}

}  // namespace pitchlab::planning
