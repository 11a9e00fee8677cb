#include "scan_gaps.hpp"

#include <cmath>
#include <vector>

namespace pitchlab::planning {
namespace {

using mapping::CellIndex;
using mapping::CellState;
using mapping::ElevationLayers;
using mapping::GridGeometry;

struct Bridge {
  std::size_t cell;
  float z_m, roughness_m, phi_x_rad, phi_y_rad;
  bool spanned;  // the gap between its bounding points is one the wheels span
};

// Ground a gap may end on: observed, free of every hazard, its inclination supported.
bool Ground(const ElevationLayers& L, const TraversabilityGrid& T, std::size_t k) {
  return L.state[k] == CellState::kObserved && T.blocked[k] == Blocked::kFree &&
         std::isfinite(L.phi_x[k]) && std::isfinite(L.phi_y[k]);
}

// Unknown, and a ray crossed it: what it is not (taller than that ray) is known.
bool CrossedGap(const ElevationLayers& L, std::size_t k) {
  return L.state[k] == CellState::kUnknown && std::isfinite(L.clearance_z[k]);
}

// The gap between ground cells `a` and `b` (`run` unknown cells strictly between them, along x
// or along y) measured between the points that bound it: from a's farthest point towards b to
// b's nearest. Up to a cell wider than the run on each side: a 0.25 m crack seen from 1.8 m left
// a two-cell run (0.2 m) whose points lay 0.24-0.32 m apart.
double GapWidth(const ElevationLayers& L, std::size_t a, std::size_t b, bool along_x, int run) {
  const double centres = (run + 1) * L.geometry.cell_m;
  if (L.point_span.empty()) return centres;  // layers made by hand: points at the centres
  const mapping::PointSpan &sa = L.point_span[a], &sb = L.point_span[b];
  return along_x ? centres - sa.hi_x + sb.lo_x : centres - sa.hi_y + sb.lo_y;
}

// The run of cells strictly between ground cells `a` and `b` (`run` of them, `stride` apart in
// storage) as bridges, when the ends lie within a step of each other and every ray over the run
// passed within a step of the line between them; else nothing.
void BridgeRun(const ElevationLayers& L, const TraversabilityGrid& T, std::size_t a,
               std::size_t stride, bool along_x, int run, std::vector<Bridge>& out) {
  const std::size_t b = a + stride * (run + 1);
  const bool spanned = GapWidth(L, a, b, along_x, run) <= MaxBridgedGap(T.config.robot);
  const double step = T.config.robot.step_max_m;
  const float za = T.z_m[a], zb = T.z_m[b];
  if (!(std::abs(zb - za) <= step)) return;
  const std::size_t first = out.size();
  for (int t = 1; t <= run; ++t) {
    const std::size_t k = a + stride * t;
    const float z = za + (zb - za) * static_cast<float>(t) / static_cast<float>(run + 1);
    if (!(L.clearance_z[k] <= z + step)) {
      out.resize(first);
      return;
    }
    out.push_back({k, z, std::max(T.roughness_m[a], T.roughness_m[b]),
                   0.5f * (T.phi_x_rad[a] + T.phi_x_rad[b]),
                   0.5f * (T.phi_y_rad[a] + T.phi_y_rad[b]), spanned});
  }
}

// Every bridgeable run along one line of `count` cells starting at storage index `start`.
void BridgeLine(const ElevationLayers& L, const TraversabilityGrid& T, std::size_t start,
                std::size_t stride, bool along_x, int count, int max_run,
                std::vector<Bridge>& out) {
  int i = 0;
  while (i < count - 1) {
    const std::size_t a = start + stride * i;
    if (!Ground(L, T, a) || !CrossedGap(L, a + stride)) {
      ++i;
      continue;
    }
    int run = 1;
    while (i + run + 1 < count && run <= max_run && CrossedGap(L, a + stride * (run + 1))) ++run;
    const int end = i + run + 1;
    if (run <= max_run && end < count && Ground(L, T, start + stride * end)) {
      BridgeRun(L, T, a, stride, along_x, run, out);
    }
    i = end;
  }
}

}  // namespace

std::size_t BridgeScanGaps(const ElevationLayers& L, TraversabilityGrid& T) {
  const GridGeometry& g = L.geometry;
  const RobotLimits& robot = T.config.robot;
  if (CoarserThanRobot(g, robot)) return 0;
  const int max_run = static_cast<int>(std::floor(MaxBridgedGap(robot) / g.cell_m + 1e-9));
  if (max_run < 1) return 0;
  // Both directions are searched on the map as observed: a bridged cell never ends another run.
  std::vector<Bridge> bridges;
  const std::size_t row = static_cast<std::size_t>(g.size_x);
  for (int j = 0; j < g.size_y; ++j) BridgeLine(L, T, j * row, 1, true, g.size_x, max_run, bridges);
  for (int i = 0; i < g.size_x; ++i) BridgeLine(L, T, i, row, false, g.size_y, max_run, bridges);
  const CostWeights& w = T.config.weights;
  std::size_t marked = 0;
  for (const Bridge& b : bridges) {
    if (std::isfinite(T.z_m[b.cell])) continue;  // bridged along x already
    T.z_m[b.cell] = b.z_m;
    T.roughness_m[b.cell] = b.roughness_m;
    T.phi_x_rad[b.cell] = b.phi_x_rad;
    T.phi_y_rad[b.cell] = b.phi_y_rad;
    T.enter_cost[b.cell] =
        static_cast<float>(w.roughness * b.roughness_m + w.inclination_x * std::abs(b.phi_x_rad) +
                           w.inclination_y * std::abs(b.phi_y_rad));
    T.blocked[b.cell] = Blocked::kFree;
    T.line_gap[b.cell] = !b.spanned;
    ++marked;
  }
  return marked;
}

}  // namespace pitchlab::planning
