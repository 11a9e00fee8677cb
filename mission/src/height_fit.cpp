#include "pitchlab/mission/height_fit.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "upper_median.hpp"

namespace pitchlab::mission {
namespace {

constexpr int kMinPointsPerCell = 3;
constexpr double kMinInlierBand_m = 0.05;

}  // namespace

std::optional<HeightOffset> FitHeightOffset(const mapping::ElevationMap& map,
                                            const std::vector<Eigen::Vector3f>& points,
                                            int min_cells) {
  const mapping::GridGeometry& g = map.geometry();
  std::vector<std::pair<std::size_t, float>> keyed;  // (cell, z), sorted: deterministic sums
  keyed.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const mapping::CellIndex c = g.IndexOf(p.x(), p.y());
    if (g.Contains(c)) keyed.emplace_back(g.Linear(c), p.z());
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<double> diff;  // scan's cell mean minus the map's
  // Ground only: a cell whose points, in the scan or in the map, rise more than a 60 deg face
  // across the cell's diagonal (mapping::LayerConfig::max_fit_slope, the elevation layers' line
  // between slope and step) holds a step (a wall, a jamb, a desk's edge), and its mean depends on
  // how much of the face each view saw. A stop facing a door a step away overlapped the map
  // mostly in such cells; their means put its floor 0.14 m low. (A 45 deg bound, a cell's width,
  // also left out the rough ground of terrain runs, whose stops then missed their height fit.)
  const double max_rise = mapping::LayerConfig{}.max_fit_slope * std::sqrt(2.0) * g.cell_m;
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    double sum = 0;
    float lo = keyed[b].second, hi = keyed[b].second;
    for (; e < keyed.size() && keyed[e].first == keyed[b].first; ++e) {
      sum += keyed[e].second;
      lo = std::min(lo, keyed[e].second);
      hi = std::max(hi, keyed[e].second);
    }
    const mapping::CellStats& m = map.at(keyed[b].first);
    if (static_cast<int>(e - b) >= kMinPointsPerCell && m.count >= kMinPointsPerCell &&
        hi - lo <= max_rise && m.max_z - m.min_z <= max_rise) {
      diff.push_back(sum / static_cast<double>(e - b) - m.mean_z);
    }
    b = e;
  }
  if (static_cast<int>(diff.size()) < min_cells) return std::nullopt;
  const double median = UpperMedian(diff);
  std::vector<double> spread;
  for (const double d : diff) spread.push_back(std::abs(d - median));
  const double band = std::max(3.0 * 1.4826 * UpperMedian(spread), kMinInlierBand_m);
  HeightOffset out;
  double sum = 0;
  for (const double d : diff) {
    if (std::abs(d - median) > band) continue;
    sum += d;
    ++out.cells;
  }
  if (out.cells < min_cells) return std::nullopt;
  out.dz_m = sum / out.cells;
  return out;
}

}  // namespace pitchlab::mission
