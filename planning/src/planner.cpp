#include "pitchlab/planning/planner.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "bucket_queue.hpp"
#include "move_cost.hpp"

namespace pitchlab::planning {
namespace {

using mapping::CellIndex;
using mapping::GridGeometry;

constexpr double kInf = std::numeric_limits<double>::infinity();
// A*'s lower bound is the relaxed octile distance (see Heuristic) times this share: under 1 by
// far more than the rounding of the summed costs, so that no cell on an optimal path gets a key
// above the goal's (finishing the goal's bucket, or popping the goal, then ends the search
// exactly); 1 - share costs 0.2 % more cells than the full bound on the benchmark map.
constexpr double kHeuristicShare = 0.999;
// Bucket width as a share of the cheapest move: a Dijkstra key then rises by two buckets or more
// per move, so no cell is expanded twice and the next bucket is complete when the current one is
// started (prefetched across the boundary). A* keys may rise by less (f = g + h rises by the
// move's cost less the drop of h), which the label-correcting buckets absorb: 0.1 % of the cells
// expanded twice on the benchmark map, against 33 x more buckets for an exact order.
constexpr double kBucketShare = 0.5;
// A bucket ring longer than this (moves far dearer than the cheapest, e.g. a huge unknown
// penalty) is replaced by a radix heap [buckets].
constexpr std::size_t kMaxRing = std::size_t{1} << 21;
// How many cells ahead in the queue their data is prefetched [cells] (8 and 12 measured alike,
// 4 and 16 slower).
constexpr std::size_t kPrefetch = 8;

// Eq. 4 and 5 for the move m out of cell a (to b), whether allowed or not, with its parts.
inline double RawEdgeCost(const TraversabilityGrid& T, std::size_t a, std::size_t b, int m,
                          CostParts* parts) {
  const double cost = (T.moves[a] >> m & 1) ? T.move_cost[a][m] : MoveCostOf(T, a, m);
  if (parts) {
    const CostWeights& w = T.config.weights;
    const bool unknown = !std::isfinite(T.z_m[b]);
    parts->length += cost - T.enter_cost[b];
    if (unknown) {
      parts->unknown += T.enter_cost[b];
    } else {
      parts->roughness += w.roughness * T.roughness_m[b];
      parts->inclination_x += w.inclination_x * std::abs(T.phi_x_rad[b]);
      parts->inclination_y += w.inclination_y * std::abs(T.phi_y_rad[b]);
      if (!T.occupancy_cost.empty()) parts->occupancy += T.occupancy_cost[b];
    }
  }
  return cost;
}

// The move index b (see TraversabilityGrid::moves) from a to b, or -1 when not 8-neighbours.
int MoveBetween(const CellIndex& a, const CellIndex& b) {
  for (int m = 0; m < 8; ++m)
    if (a.i + kMoveDi[m] == b.i && a.j + kMoveDj[m] == b.j) return m;
  return -1;
}

std::string Where(const Eigen::Vector2d& p) {
  std::ostringstream os;
  os << std::setprecision(10) << "(" << p.x() << ", " << p.y() << ")";  // UTM eastings whole
  return os.str();
}

// One search's labels: tentative cost and a visited bit per cell. The costs are padded by a row
// and a cell on either side, so that k + delta of every move of every cell k is inside the array
// (a move off the grid costs +inf and never wins: no bounds test). No parent pointers: the path
// is read back from the costs (see Predecessor), which saves a store per relaxation.
class Labels {
 public:
  Labels(std::size_t cells, int size_x)
      : pad_(static_cast<std::size_t>(size_x) + 1),
        padded_(cells + 2 * pad_, kInf),
        visited_((cells + 63) / 64, 0) {}
  Labels(const Labels&) = delete;
  Labels& operator=(const Labels&) = delete;

  /// Cost labels, indexable from -(size_x + 1) to cells + size_x.
  double* Dist() { return padded_.data() + pad_; }
  double Dist(std::uint32_t k) const { return padded_[pad_ + k]; }
  std::uint64_t* VisitedBits() { return visited_.data(); }
  bool Visited(std::uint32_t k) const { return visited_[k >> 6] >> (k & 63) & 1; }
  void Visit(std::uint32_t k) { visited_[k >> 6] |= std::uint64_t{1} << (k & 63); }

 private:
  std::size_t pad_;
  std::vector<double> padded_;
  std::vector<std::uint64_t> visited_;
};

// A*'s lower bound: kHeuristicShare times the distance to the goal on an obstacle-free 8-grid
// whose straight moves cost a' = min(a, b) and diagonal ones b' = min(b, 2a'), with a and b the
// cheapest straight and diagonal moves of the map. Every real move costs at least its relaxed
// one, so h is admissible and consistent: h(u) <= c(u,v) + h(v). Zero for Dijkstra.
struct Heuristic {
  double straight = 0, diagonal = 0;  // per move [1]
  int goal_i = 0, goal_j = 0;
  double operator()(int i, int j) const {
    const int dx = std::abs(i - goal_i), dy = std::abs(j - goal_j);
    const int lo = std::min(dx, dy), hi = std::max(dx, dy);
    return straight * (hi - lo) + diagonal * lo;  // octile distance, weighted
  }
};

Heuristic MakeHeuristic(const TraversabilityGrid& T, const CellIndex& goal, bool astar) {
  Heuristic h{0, 0, goal.i, goal.j};
  const double a = T.min_straight_cost, b = T.min_diagonal_cost;
  if (!astar || !std::isfinite(std::min(a, b))) return h;
  const double a_relaxed = std::min(a, b);
  h.straight = kHeuristicShare * a_relaxed;
  h.diagonal = kHeuristicShare * std::min(b, 2 * a_relaxed);
  return h;
}

// Expands one cell (Algorithm 2's inner loop): its 8 precomputed move costs
// (TraversabilityGrid::move_cost, +inf where not allowed) added to its cost and compared with the
// neighbours' labels, no mask, no bounds test, no branch; then the better offers are stored and
// queued at g (Dijkstra) or g + h - h(start) (A*). A neighbour lowered after its own expansion
// (A* inside the current bucket) loses its visited bit, to be expanded again.
template <bool kAStar>
struct Relaxer {
  const MoveCosts* cost;
  double* dist;             // Labels::Dist()
  std::uint64_t* visited;   // Labels::VisitedBits()
  std::ptrdiff_t delta[8];  // linear index step of each move
  std::ptrdiff_t row;       // size_x
  unsigned size_x;
  Heuristic h;
  double h_start;

  void Prefetch(std::uint32_t k) const {
    __builtin_prefetch(cost + k);
    __builtin_prefetch(dist + k - row);  // the labels of the rows below and above
    __builtin_prefetch(dist + k + row);
  }

  template <typename Queue>
  void operator()(std::uint32_t k, Queue& queue) const {
    const double gk = dist[k];
    const float* c = cost[k].to;
    unsigned better = 0;
    for (int b = 0; b < 8; ++b)
      better |= static_cast<unsigned>(gk + static_cast<double>(c[b]) < dist[k + delta[b]]) << b;
    if (better == 0) return;
    int ci = 0, cj = 0;
    if constexpr (kAStar) {
      cj = static_cast<int>(k / size_x);
      ci = static_cast<int>(k - static_cast<unsigned>(cj) * size_x);
    }
    do {
      const int b = __builtin_ctz(better);
      better &= better - 1;
      const auto kn = static_cast<std::uint32_t>(k + delta[b]);
      const double g = gk + static_cast<double>(c[b]);
      dist[kn] = g;
      double key = g;
      if constexpr (kAStar) {
        // Only A* lowers an expanded cell: Dijkstra's keys rise by two buckets or more per move.
        visited[kn >> 6] &= ~(std::uint64_t{1} << (kn & 63));
        key += h(ci + kMoveDi[b], cj + kMoveDj[b]) - h_start;
      }
      queue.Push(key, kn);
    } while (better != 0);
  }
};

// Algorithm 2 from ks over the buckets, until the bucket in which kt was settled is worked
// through (every cell keyed below the goal is then final: no key of an optimal path's cell
// exceeds the goal's, see kHeuristicShare); returns the cells expanded. A bucket is worked
// through in any order, label-correcting: a cell lowered into the current bucket after its
// expansion is queued there again.
template <bool kAStar>
std::size_t SearchBuckets(const Relaxer<kAStar>& relax, std::uint32_t ks, std::uint32_t kt,
                          BucketQueue& queue, Labels& L) {
  std::size_t expanded = 0;
  bool goal_settled = false;
  queue.Push(0.0, ks);
  do {
    std::vector<std::uint32_t>& bucket = queue.Current();
    // Drop the stale entries (cells expanded in an earlier bucket, queued again at a higher key)
    // first, without a branch: the expansion loop then has no unpredictable test.
    std::size_t live = 0;
    for (const std::uint32_t k : bucket) {
      bucket[live] = k;
      live += !L.Visited(k);
    }
    bucket.resize(live);
    for (std::size_t n = 0; n < bucket.size(); ++n) {  // it may grow as we go
      // The queue says which cells come next: fetch their move costs and labels early (the
      // search is bound by memory latency), on into the next bucket.
      const std::size_t ahead = n + kPrefetch, size = bucket.size();
      if (ahead < size) {
        relax.Prefetch(bucket[ahead]);
      } else if (ahead - size < queue.Following().size()) {
        relax.Prefetch(queue.Following()[ahead - size]);
      }
      const std::uint32_t k = bucket[n];
      if (L.Visited(k)) continue;  // queued twice in this bucket
      L.Visit(k);
      ++expanded;
      if (k == kt) {
        goal_settled = true;
        continue;
      }
      relax(k, queue);
    }
  } while (!goal_settled && queue.Advance());
  return expanded;
}

// The same with a radix heap: cells in key order, until kt is popped.
template <bool kAStar>
std::size_t SearchHeap(const Relaxer<kAStar>& relax, std::uint32_t ks, std::uint32_t kt,
                       RadixHeap& queue, Labels& L) {
  std::size_t expanded = 0;
  queue.Push(0.0, ks);
  while (!queue.Empty()) {
    const std::uint32_t k = queue.Pop();
    if (L.Visited(k)) continue;  // a stale entry: the cell was expanded at a lower key
    L.Visit(k);
    ++expanded;
    if (k == kt) break;
    relax(k, queue);
  }
  return expanded;
}

// Algorithm 2 from ks to kt with keys g + h - h(start) (g for Dijkstra), which never fall along a
// move by more than rounding (h is consistent): a bucket queue whose width is kBucketShare of the
// cheapest move, or a radix heap when the ring of buckets would be too long. Returns the cells
// expanded.
template <bool kAStar>
std::size_t RunSearch(const TraversabilityGrid& T, std::uint32_t ks, std::uint32_t kt,
                      const Heuristic& h, Labels& L) {
  const GridGeometry& g = T.geometry;
  Relaxer<kAStar> relax{T.move_cost.data(),
                        L.Dist(),
                        L.VisitedBits(),
                        {},
                        g.size_x,
                        static_cast<unsigned>(g.size_x),
                        h,
                        0.0};
  for (int b = 0; b < 8; ++b)
    relax.delta[b] = kMoveDi[b] + static_cast<std::ptrdiff_t>(kMoveDj[b]) * g.size_x;
  const CellIndex s = g.FromLinear(ks);
  if constexpr (kAStar) relax.h_start = h(s.i, s.j);
  L.Dist()[ks] = 0.0;
  const double width = kBucketShare * std::min(T.min_straight_cost, T.min_diagonal_cost);
  const double span = (T.max_edge_cost + h.diagonal) / width + 3;  // a move's largest key rise
  if (std::isfinite(width) && width > 0 && span < double(kMaxRing)) {
    BucketQueue queue(width, static_cast<std::size_t>(span));
    return SearchBuckets<kAStar>(relax, ks, kt, queue, L);
  }
  RadixHeap queue;
  return SearchHeap<kAStar>(relax, ks, kt, queue, L);
}

// The settled neighbour u of v that minimises cost(u) + Eq. 5 cost of u -> v: v's parent in the
// search (the relaxation that set v's cost used exactly that sum, with u already final), or an
// equally cheap one. Every move costs > 0, so costs fall strictly along the chain back to start.
std::uint32_t Predecessor(const TraversabilityGrid& T, const Labels& L, std::uint32_t v) {
  const GridGeometry& g = T.geometry;
  const CellIndex cv = g.FromLinear(v);
  std::uint32_t best = v;
  double best_cost = kInf;
  for (int b = 0; b < 8; ++b) {
    const CellIndex cu{cv.i - kMoveDi[b], cv.j - kMoveDj[b]};
    if (!g.Contains(cu)) continue;
    const auto u = static_cast<std::uint32_t>(g.Linear(cu));
    if (!(T.moves[u] >> b & 1) || !L.Visited(u)) continue;
    const double c = L.Dist(u) + static_cast<double>(T.move_cost[u][b]);
    if (c < best_cost) best_cost = c, best = u;
  }
  if (best == v) throw std::logic_error("plan path: a settled cell has no settled predecessor");
  return best;
}

Path Reconstruct(const TraversabilityGrid& T, const Labels& L, std::uint32_t start,
                 std::uint32_t goal) {
  const GridGeometry& g = T.geometry;
  Path path;
  path.cost = L.Dist(goal);
  std::vector<std::uint32_t> ks;
  for (std::uint32_t k = goal; k != start; k = Predecessor(T, L, k)) ks.push_back(k);
  ks.push_back(start);
  std::reverse(ks.begin(), ks.end());
  for (std::size_t n = 0; n < ks.size(); ++n) {
    const CellIndex c = g.FromLinear(ks[n]);
    const Eigen::Vector2d xy = g.CenterOf(c);
    path.cells.push_back(c);
    path.waypoints.push_back({xy.x(), xy.y(), T.z_m[ks[n]]});
    if (std::isfinite(T.z_m[ks[n]]))
      path.max_inclination_rad = std::max(path.max_inclination_rad, T.Tilt(ks[n]));
    if (n == 0) continue;
    const CellIndex p = g.FromLinear(ks[n - 1]);
    CostParts before = path.parts;
    RawEdgeCost(T, ks[n - 1], ks[n], MoveBetween(p, c), &path.parts);
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
  const auto ks = static_cast<std::uint32_t>(g.Linear(s)),
             kt = static_cast<std::uint32_t>(g.Linear(t));
  if (!T.Free(ks) && T.blocked[ks] != Blocked::kUnknown)
    return fail(NoPath::Reason::kStartBlocked,
                "start " + Where(start_m) + " is blocked: " + ToString(T.blocked[ks]));
  if (!T.Free(kt))
    return fail(NoPath::Reason::kGoalBlocked,
                "goal " + Where(goal_m) + " is blocked: " + ToString(T.blocked[kt]));

  const bool astar = algorithm == Algorithm::kAStar;
  const Heuristic h = MakeHeuristic(T, t, astar);
  Labels labels(g.cell_count(), g.size_x);
  const std::size_t expanded =
      astar ? RunSearch<true>(T, ks, kt, h, labels) : RunSearch<false>(T, ks, kt, h, labels);
  if (!labels.Visited(kt)) {
    return fail(NoPath::Reason::kDisconnected,
                "no path from " + Where(start_m) + " to " + Where(goal_m) +
                    ": the goal is not connected to the start through cells the robot may enter");
  }
  Path path = Reconstruct(T, labels, ks, kt);
  path.algorithm = algorithm;
  path.expanded = expanded;
  return path;
}

double EdgeCost(const TraversabilityGrid& T, std::size_t a, std::size_t b, CostParts* parts) {
  const GridGeometry& g = T.geometry;
  const CellIndex ca = g.FromLinear(a), cb = g.FromLinear(b);
  const int m = MoveBetween(ca, cb);
  if (m < 0 || !(T.moves[a] >> m & 1)) return std::nan("");
  return RawEdgeCost(T, a, b, m, parts);
}

std::vector<GraphEdge> ListEdges(const TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  std::vector<GraphEdge> edges;
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    if (!T.Free(k)) continue;
    const CellIndex c = g.FromLinear(k);
    for (int m = 0; m < 8; ++m) {
      if (!(T.moves[k] >> m & 1)) continue;
      const std::size_t kn = g.Linear({c.i + kMoveDi[m], c.j + kMoveDj[m]});
      edges.push_back({static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(kn),
                       RawEdgeCost(T, k, kn, m, nullptr)});
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
    if (!g.Contains(p)) throw std::invalid_argument("evaluate path: a path cell is off the grid");
    const int m = MoveBetween(p, c);
    if (m < 0) throw std::invalid_argument("evaluate path: consecutive cells are not neighbours");
    out.cost += RawEdgeCost(T, g.Linear(p), k, m, nullptr);
  }
  return out;
}

}  // namespace pitchlab::planning
