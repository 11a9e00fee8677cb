#include "pitchlab/mapping/cloud_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include "fast_pipeline.hpp"
#include "voxel_hash.hpp"

namespace pitchlab::mapping {
namespace {

constexpr std::size_t kMinPoints = 20;
// Points measured per statistic: the medians of 1000 samples are good to a few per cent, and
// the cost stays far below one ICP run.
constexpr int kSamples = 1000;

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Median nearest-neighbour distance of the sampled points. The hash needs a cell at least the
// distance sought: start at 2 % of the median range (a 0.5 deg scanner's beams lie 0.9 % of the
// range apart) and double it until most samples find a neighbour (a coarser scanner).
double MedianSpacing(const PointCloud& cloud, const std::vector<int>& samples, double range_m) {
  double cell = std::max(0.02 * range_m, 1e-9);
  for (int attempt = 0; attempt < 12; ++attempt, cell *= 2) {
    const VoxelHashIndex index(cloud, cell);
    std::vector<double> d;
    std::vector<int> nn;
    for (int i : samples) {
      nn.clear();
      index.Radius(cloud[i], static_cast<float>(cell), nn);
      double best = INFINITY;
      for (int j : nn) {
        if (j == i) continue;
        const double dj = (cloud[j] - cloud[i]).norm();
        if (dj > 0) best = std::min(best, dj);  // duplicates say nothing of the spacing
      }
      if (std::isfinite(best)) d.push_back(best);
    }
    if (d.size() * 2 >= samples.size()) return Median(std::move(d));
  }
  return 0;
}

// RMS distance of a neighbourhood to its best-fit plane, or NaN when the neighbourhood is not a
// surface patch: fewer than 10 points, or spread along a line (a single scan line: its best plane
// takes up one direction of the noise) with the second eigenvalue under a tenth of the first.
double PlaneResidual(const PointCloud& cloud, const std::vector<int>& nn) {
  if (nn.size() < 10) return NAN;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(Scatter(cloud, nn) / static_cast<double>(nn.size()), Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = eig.eigenvalues();  // ascending
  if (!(ev(1) >= 0.1 * ev(2))) return NAN;
  return std::sqrt(std::max(0.0, ev(0)));
}

}  // namespace

CloudStatistics MeasureCloud(const PointCloud& cloud, const Eigen::Vector3f& sensor) {
  PointCloud finite;
  finite.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud) {
    if (p.allFinite()) finite.push_back(p);
  }
  CloudStatistics out;
  out.points = finite.size();
  if (finite.size() < kMinPoints) return out;
  std::vector<double> ranges(finite.size());
  for (std::size_t i = 0; i < finite.size(); ++i) ranges[i] = (finite[i] - sensor).norm();
  out.median_range_m = Median(std::move(ranges));

  const std::vector<int> samples = EvenIndices(finite.size(), kSamples);
  out.spacing_m = MedianSpacing(finite, samples, out.median_range_m);
  if (!(out.spacing_m > 0)) return out;
  // Eight spacings: wide enough to reach the next beam of a scanner whose lines are five times
  // denser than its beams (a nodding LMS at 1 deg beams, 0.2 deg lines), narrow enough that most
  // neighbourhoods lie on one surface; the 32 nearest keep the patch local where it is dense.
  const double radius = 8 * out.spacing_m;
  const VoxelHashIndex index(finite, radius);
  std::vector<double> residuals;
  std::vector<int> nn;
  std::vector<std::pair<float, int>> by_distance;
  for (int i : samples) {
    nn.clear();
    index.Radius(finite[i], static_cast<float>(radius), nn);
    if (nn.size() > 32) {
      by_distance.clear();
      for (int j : nn) by_distance.emplace_back((finite[j] - finite[i]).squaredNorm(), j);
      std::nth_element(by_distance.begin(), by_distance.begin() + 32, by_distance.end());
      nn.clear();
      for (int k = 0; k < 32; ++k) nn.push_back(by_distance[k].second);
    }
    const double r = PlaneResidual(finite, nn);
    if (std::isfinite(r)) residuals.push_back(r);
  }
  out.noise_samples = residuals.size();
  out.noise_m = Median(std::move(residuals));
  return out;
}

double ShareWithin(const PointCloud& target, const PointCloud& source,
                   const Eigen::Isometry3d& T_target_source, double distance_m) {
  if (source.empty()) return 0;
  PointCloud finite;
  finite.reserve(target.size());
  for (const Eigen::Vector3f& p : target) {
    if (p.allFinite()) finite.push_back(p);
  }
  const VoxelHashIndex index(finite, distance_m);
  const Eigen::Isometry3f T = T_target_source.cast<float>();
  const float d = static_cast<float>(distance_m);
  std::size_t within = 0;
  float d2 = 0;
  for (const Eigen::Vector3f& p : source) {
    if (p.allFinite() && index.Nearest(T * p, d, d2) >= 0) ++within;
  }
  return static_cast<double>(within) / static_cast<double>(source.size());
}

}  // namespace pitchlab::mapping
