#include "pitchlab/mapping/ground_level.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "half_normal_quantile.hpp"
#include "up_plane_fit.hpp"

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {
namespace {

struct Plane {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  // up normal
  double d = 0;                                  // n . p = d
  double Distance(const Eigen::Vector3f& p) const { return n.dot(p.cast<double>()) - d; }
};

// Total least squares plane through `points`, normal turned up.
Plane FitPlane(const std::vector<Eigen::Vector3f>& points) {
  const auto [n, d] = UpPlaneThrough(points);
  return Plane{n, d};
}

// The candidates: finite points below the sensor whose horizontal distance from it lies within
// [min_radius_m, max_radius_m].
std::vector<Eigen::Vector3f> PointsInBand(const std::vector<Eigen::Vector3f>& points_m,
                                          const Eigen::Vector3f& sensor_m,
                                          const GroundLevelConfig& config) {
  std::vector<Eigen::Vector3f> band;
  for (const Eigen::Vector3f& p : points_m) {
    if (!p.allFinite() || p.z() >= sensor_m.z()) continue;
    const float r = (p - sensor_m).head<2>().norm();
    if (r >= config.min_radius_m && r <= config.max_radius_m) band.push_back(p);
  }
  return band;
}

// One sample per cell of `cell_m` (the median height of its points at their mean position), in
// the order of the cells' keys (deterministic). The floor is weighed by its area, not by the point
// density, which a nodding scan piles up near the sensor (the 3DTK corridor's floor within 1.5 m
// holds most points, and reads 6 deg steeper there than beyond: a plane through the points
// levelled the near floor and left the rest 4 deg off).
std::vector<Eigen::Vector3f> CellSamples(const std::vector<Eigen::Vector3f>& points,
                                         double cell_m) {
  std::unordered_map<std::int64_t, std::vector<Eigen::Vector3f>> cells;
  const double inv = 1.0 / cell_m;
  for (const Eigen::Vector3f& p : points) {
    const std::int64_t i = static_cast<std::int64_t>(std::floor(p.x() * inv));
    const std::int64_t j = static_cast<std::int64_t>(std::floor(p.y() * inv));
    cells[i * 1000003 + j].push_back(p);
  }
  std::vector<std::pair<std::int64_t, Eigen::Vector3f>> samples;
  for (auto& [key, in_cell] : cells) {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& p : in_cell) mean += p;
    mean /= static_cast<float>(in_cell.size());
    std::nth_element(
        in_cell.begin(), in_cell.begin() + in_cell.size() / 2, in_cell.end(),
        [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return a.z() < b.z(); });
    samples.emplace_back(key, Eigen::Vector3f(mean.x(), mean.y(), in_cell[in_cell.size() / 2].z()));
  }
  std::sort(samples.begin(), samples.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3f> out;
  for (const auto& s : samples) out.push_back(s.second);
  return out;
}

// The best plane hypothesis and its score: the `quantile`-th smallest absolute distance of the
// candidates to it [m].
struct Hypothesis {
  Plane plane;
  double score_m = std::numeric_limits<double>::infinity();
};

// Random 3-point planes of `candidates` within max_tilt_rad of level and below the sensor, scored
// by the quantile of their distances (least quantile of squares: no threshold to guess); the best.
// Its score is infinite when no hypothesis qualified. Scored on at most 4000 candidates (a quantile
// of 4000 distances is known to well under 1 %).
Hypothesis BestHypothesis(const std::vector<Eigen::Vector3f>& candidates,
                          const Eigen::Vector3f& sensor_m, const GroundLevelConfig& config,
                          std::mt19937& rng) {
  std::vector<Eigen::Vector3f> sample = candidates;
  if (sample.size() > 4000) {
    std::shuffle(sample.begin(), sample.end(), rng);
    sample.resize(4000);
  }
  const double cos_max_tilt = std::cos(config.max_tilt_rad);
  std::uniform_int_distribution<std::size_t> pick(0, candidates.size() - 1);
  std::vector<double> distances(sample.size());
  const std::size_t q_index = static_cast<std::size_t>(config.quantile * (sample.size() - 1));
  Hypothesis best;
  for (int h = 0; h < config.hypotheses; ++h) {
    const Eigen::Vector3d a = candidates[pick(rng)].cast<double>();
    const Eigen::Vector3d b = candidates[pick(rng)].cast<double>();
    const Eigen::Vector3d c = candidates[pick(rng)].cast<double>();
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-6) continue;  // collinear or repeated points
    n.normalize();
    if (n.z() < 0) n = -n;
    if (n.z() < cos_max_tilt) continue;
    const Plane plane{n, n.dot(a)};
    if (plane.Distance(sensor_m) <= 0) continue;  // the floor is below the sensor
    for (std::size_t k = 0; k < sample.size(); ++k) distances[k] = std::abs(plane.Distance(sample[k]));
    std::nth_element(distances.begin(), distances.begin() + q_index, distances.end());
    if (distances[q_index] < best.score_m) best.score_m = distances[q_index], best.plane = plane;
  }
  return best;
}

// The plane refined by total least squares on the candidates within 3 sigma, sigma the RMS distance
// of the current inliers, until the inliers stop changing (at most 30 rounds).
struct Refined {
  Plane plane;
  double sigma_m = 0;      // RMS distance of the inliers [m]
  double threshold_m = 0;  // the last fit's inlier distance [m]; 0 without a fit
  std::vector<Eigen::Vector3f> inliers;
};

Refined RefinePlane(const std::vector<Eigen::Vector3f>& candidates, const Hypothesis& best,
                    const GroundLevelConfig& config) {
  Refined r;
  r.plane = best.plane;
  // The quantile's distance is that of a Gaussian with this sigma if every candidate were floor;
  // others only make it larger, so the first threshold is generous and the loop tightens it.
  r.sigma_m = std::max(best.score_m / HalfNormalQuantile(config.quantile), 1e-4);
  std::size_t previous = 0;
  for (int iteration = 0; iteration < 30; ++iteration) {
    const double threshold = 3.0 * r.sigma_m;
    r.inliers.clear();
    for (const Eigen::Vector3f& p : candidates)
      if (std::abs(r.plane.Distance(p)) < threshold) r.inliers.push_back(p);
    if (r.inliers.size() < config.min_points) break;
    r.plane = FitPlane(r.inliers);
    double ss = 0;
    for (const Eigen::Vector3f& p : r.inliers) ss += r.plane.Distance(p) * r.plane.Distance(p);
    // 1e-4 m: far below any laser's noise, keeps a noise-free (synthetic) floor's threshold
    // above rounding.
    r.sigma_m = std::max(std::sqrt(ss / r.inliers.size()), 1e-4);
    r.threshold_m = threshold;
    if (r.inliers.size() == previous) break;
    previous = r.inliers.size();
  }
  return r;
}

}  // namespace

Result<GroundLevel> FitGroundLevel(const std::vector<Eigen::Vector3f>& points_m,
                                   const Eigen::Vector3f& sensor_m,
                                   const GroundLevelConfig& config) {
  const std::vector<Eigen::Vector3f> candidates =
      CellSamples(PointsInBand(points_m, sensor_m, config), config.cell_m);
  GroundLevel level;
  level.candidates = candidates.size();
  if (candidates.size() < config.min_points) {
    return Fail(Error::Code::kFailed, "ground levelling: " + std::to_string(candidates.size()) +
                                          " cells with points below the sensor within " +
                                          NumberText(config.min_radius_m) + ".." +
                                          NumberText(config.max_radius_m) +
                                          " m of it, too few to find the floor (need " +
                                          std::to_string(config.min_points) + ")");
  }
  std::mt19937 rng(config.seed);
  const Hypothesis best = BestHypothesis(candidates, sensor_m, config, rng);
  if (!std::isfinite(best.score_m)) {
    return Fail(Error::Code::kFailed, "ground levelling: no plane within " +
                                          NumberText(config.max_tilt_rad * 180 / M_PI) +
                                          " deg of level lies below the sensor among " +
                                          std::to_string(candidates.size()) + " points");
  }
  const Refined fit = RefinePlane(candidates, best, config);
  if (fit.inliers.size() < config.min_points) {
    return Fail(Error::Code::kFailed, "ground levelling: only " +
                                          std::to_string(fit.inliers.size()) + " of " +
                                          std::to_string(candidates.size()) +
                                          " points near the sensor lie on one floor plane");
  }
  level.normal = fit.plane.n;
  level.offset_m = fit.plane.d;
  level.tilt_rad = std::acos(std::clamp(fit.plane.n.z(), -1.0, 1.0));
  level.residual_m = fit.sigma_m;
  level.threshold_m = fit.threshold_m;
  level.inliers = fit.inliers.size();
  level.sensor_height_m = fit.plane.Distance(sensor_m);
  level.R_level =
      Eigen::Quaterniond::FromTwoVectors(fit.plane.n, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return level;
}

}  // namespace pitchlab::mapping
