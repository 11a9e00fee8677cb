#include "fast_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "pitchlab/mapping/parallel_for.hpp"
#include "se3_perturbation.hpp"

namespace pitchlab::mapping {
namespace {

constexpr int kBins = 11;  // per FPFH sub-histogram (pcl::FPFHSignature33)
constexpr float kPi = 3.14159265358979f;

int Bin(float unit) { return std::clamp(static_cast<int>(std::floor(unit * kBins)), 0, kBins - 1); }

// The FPFH bin of an angle in [-pi, pi].
int AngleBin(float angle) { return Bin((angle + kPi) / (2 * kPi)); }

// atan(z) for z in [-1, 1]: an odd minimax polynomial, within 1.8e-6 rad of atan on every float in
// [0, 1] when evaluated in float (checked exhaustively against double atan), and odd in float too.
float AtanUnit(float z) {
  const float z2 = z * z;
  return z * (0.99997726f +
              z2 * (-0.33262347f +
                    z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f + z2 * -0.01172120f)))));
}

// Below this, a vector's angle is left to atan2 (Atan2Polynomial divides by at least this).
constexpr float kTinyVector = 1e-20f;

// std::atan2(y, x) within 5e-6 rad where max(|x|, |y|) >= kTinyVector: AtanUnit's 1.8e-6, the
// quotient's rounding (< 2e-7: atan's slope is at most 1) and the sums' (< 4e-7), with atan2's
// quadrants and signs. One formula for every octant, atan2(|y|, |x|) = pi/4 + atan((|y| - |x|) /
// (|y| + |x|)), and the left half by a product with 0 or 1: no branch, for the quadrants of
// neighbouring points' pairs follow no pattern a branch predictor could learn.
float Atan2Polynomial(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float right = 0.25f * kPi + AtanUnit((ay - ax) / std::max(ay + ax, kTinyVector));
  const float left = static_cast<float>(std::signbit(x));
  return std::copysign(right + left * (kPi - 2 * right), y);  // pi - right where x < 0
}

// How near (in bins) an angle's bin position may come to an edge between two bins before its bin
// is taken from atan2 itself: 5e-4 bins is 2.9e-4 rad, against the polynomial's 5e-6 rad, atan2f's
// < 1 ulp and AngleBin's float rounding (< 1e-5 bins): 25x room.
constexpr float kEdgeMarginBins = 5e-4f;

// AngleBin(std::atan2(y, x)), bit for bit: AngleBin's edges are where its bin position (angle +
// pi) * 11 / 2pi crosses 1 .. 10, and its float operations never decrease with the angle, so an
// angle whose approximate position lies farther than the margin from every inner edge has the bin
// atan2's value (within the margin) has. Only angles near an edge (~0.1 % of pairs) and tiny
// vectors call atan2.
int AngleBinFast(float y, float x) {
  const float position = (Atan2Polynomial(y, x) + kPi) * (kBins / (2 * kPi));
  const int bin = std::clamp(static_cast<int>(position), 0, kBins - 1);
  const bool near_lower = (bin > 0) & (position - static_cast<float>(bin) <= kEdgeMarginBins);
  const bool near_upper =
      (bin < kBins - 1) & (static_cast<float>(bin + 1) - position <= kEdgeMarginBins);
  const bool tiny = std::max(std::fabs(x), std::fabs(y)) < kTinyVector;
  if (near_lower | near_upper | tiny) [[unlikely]] return AngleBin(std::atan2(y, x));
  return bin;
}

}  // namespace

float internal::ApproxAtan2(float y, float x) { return Atan2Polynomial(y, x); }
int internal::AngleBinOfAtan2(float y, float x) { return AngleBinFast(y, x); }

namespace {

// pcl::computePairFeatures' Darboux-frame angles between two oriented points, as FPFH bins: f1's
// bin (the angle), f2's and f3's (cosines).
bool PairFeatureBins(const Eigen::Vector3f& p1, const Eigen::Vector3f& n1,
                     const Eigen::Vector3f& p2, const Eigen::Vector3f& n2, int& b1, int& b2,
                     int& b3) {
  Eigen::Vector3f dp = p2 - p1;
  const float d = dp.norm();
  if (d <= 0) return false;
  Eigen::Vector3f a = n1, b = n2;
  const float angle1 = a.dot(dp) / d, angle2 = b.dot(dp) / d;
  float f3 = angle1;
  // acos(|angle1|) > acos(|angle2|), which acosf's never increasing on [0, 1] (checked on every
  // float of this glibc) makes false unless |angle1| < |angle2|: the acos only then.
  if (std::fabs(angle1) < std::fabs(angle2) &&
      std::acos(std::fabs(angle1)) > std::acos(std::fabs(angle2))) {
    std::swap(a, b);
    dp = -dp;
    f3 = -angle2;
  }
  Eigen::Vector3f v = dp.cross(a);
  const float vn = v.norm();
  if (vn <= 0) return false;
  v /= vn;
  const Eigen::Vector3f w = a.cross(v);
  const float f2 = v.dot(b);
  b1 = AngleBinFast(w.dot(b), a.dot(b));
  b2 = Bin((f2 + 1) * 0.5f);
  b3 = Bin((f3 + 1) * 0.5f);
  return true;
}

// Rigid fit of source onto target points (Umeyama, no scale).
Eigen::Isometry3d FitRigid(const PointCloud& source, const PointCloud& target,
                           const std::vector<Correspondence>& corrs) {
  Eigen::Matrix3Xd s(3, corrs.size()), t(3, corrs.size());
  for (std::size_t i = 0; i < corrs.size(); ++i) {
    s.col(i) = source[corrs[i].source].cast<double>();
    t.col(i) = target[corrs[i].target].cast<double>();
  }
  Eigen::Isometry3d T;
  T.matrix() = Eigen::umeyama(s, t, false);
  return T;
}

int CountInliers(const PointCloud& source, const PointCloud& target,
                 const std::vector<Correspondence>& corrs, const Eigen::Isometry3d& T,
                 float inlier_m, std::vector<Correspondence>* inliers) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  const float r2 = inlier_m * inlier_m;
  int n = 0;
  for (const Correspondence& c : corrs) {
    if ((Tf * source[c.source] - target[c.target]).squaredNorm() < r2) {
      ++n;
      if (inliers) inliers->push_back(c);
    }
  }
  return n;
}

// Correspondences of `source` under T: (transformed point, target index) within the gate.
struct Pair {
  Eigen::Vector3d p, t, n;
};
const VoxelHashIndex& IndexFor(const IcpTarget& target, float gate_m) {
  return gate_m <= target.fine_cell_m ? target.fine : target.coarse;
}

// The nearest-neighbour searches run on the machine's cores, each source point's target index
// into its own slot; the pairs are then taken in source order, as a single thread would.
void FindPairs(const IcpTarget& target, const PointCloud& source, const Eigen::Isometry3d& T,
               float gate_m, std::vector<Pair>& pairs) {
  constexpr std::size_t kPointsPerBlock = 512;  // ~0.2 ms of searches: a thread's start is 1/10
  pairs.clear();
  const Eigen::Isometry3f Tf = T.cast<float>();
  const VoxelHashIndex& index = IndexFor(target, gate_m);
  // The caller's buffers, kept between iterations (the helpers write the caller's, not theirs).
  thread_local std::vector<int> nearest_buffer;
  thread_local PointCloud moved_buffer;
  std::vector<int>& nearest = nearest_buffer;
  PointCloud& moved = moved_buffer;
  nearest.resize(source.size());
  moved.resize(source.size());
  ParallelFor(source.size(), kPointsPerBlock, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      moved[i] = Tf * source[i];
      float d2 = 0;
      nearest[i] = index.Nearest(moved[i], gate_m, d2);
    }
  });
  target.normals.Make(nearest);
  for (std::size_t i = 0; i < source.size(); ++i) {
    const int j = nearest[i];
    if (j < 0 || !target.normals[j].allFinite()) continue;
    pairs.push_back({moved[i].cast<double>(), target.points[j].cast<double>(),
                     target.normals[j].cast<double>()});
  }
}

}  // namespace

bool PriorRegion::Contains(const Eigen::Isometry3d& T) const {
  const Eigen::Isometry3d d = T_target_source.inverse() * T;
  return d.translation().norm() <= translation_m &&
         Eigen::AngleAxisd(d.linear()).angle() <= rotation_rad;
}

namespace {
// Scatter of the points point(0 .. n - 1), summed in that order.
template <typename Point>
Eigen::Matrix3d ScatterOf(std::size_t n, Point point) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) mean += point(k).template cast<double>();
  mean /= static_cast<double>(std::max<std::size_t>(1, n));
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d d = point(k).template cast<double>() - mean;
    scatter += d * d.transpose();
  }
  return scatter;
}
}  // namespace

Eigen::Matrix3d Scatter(const PointCloud& cloud, const std::vector<int>& indices) {
  return ScatterOf(indices.size(), [&](std::size_t k) { return cloud[indices[k]]; });
}

// Both loops below run on the machine's cores (ParallelFor): every point's normal, SPFH and FPFH
// depend on the point and its neighbours alone, so the result is a single thread's. They were
// 60 % of a registration's CPU (features and normals; terrain seed 1, 20 stops).
constexpr std::size_t kPointsPerBlock = 256;

namespace {

// The PCA normal at `p` over `radius_m`, facing `viewpoint`; NaN with fewer than 5 neighbours.
// `nn`: the caller's buffer for the neighbours themselves (Scatter's order, read in line).
Eigen::Vector3f NormalAt(const Eigen::Vector3f& p, const VoxelHashIndex& index, float radius_m,
                         const Eigen::Vector3f& viewpoint, std::vector<Eigen::Vector3f>& nn) {
  nn.clear();
  index.RadiusPoints(p, radius_m, nn);
  if (nn.size() < 5) return Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(ScatterOf(nn.size(), [&](std::size_t k) { return nn[k]; }));
  Eigen::Vector3f n = eig.eigenvectors().col(0).cast<float>();
  if (n.dot(viewpoint - p) < 0) n = -n;
  return n;
}

}  // namespace

Normals EstimateNormals(const PointCloud& cloud, const VoxelHashIndex& index, float radius_m,
                        const Eigen::Vector3f& viewpoint) {
  Normals normals(cloud.size());
  ParallelFor(cloud.size(), kPointsPerBlock, [&](std::size_t begin, std::size_t end) {
    std::vector<Eigen::Vector3f> nn;
    for (std::size_t i = begin; i < end; ++i) {
      normals[i] = NormalAt(cloud[i], index, radius_m, viewpoint, nn);
    }
  });
  return normals;
}

LazyNormals::LazyNormals(const PointCloud& cloud, const VoxelHashIndex& index, float radius_m,
                         const Eigen::Vector3f& viewpoint)
    : cloud_(cloud),
      index_(index),
      radius_m_(radius_m),
      viewpoint_(viewpoint),
      normals_(cloud.size()),
      made_(cloud.size(), 0) {}

void LazyNormals::Make(const std::vector<int>& indices) const {
  missing_.clear();
  for (const int i : indices) {
    if (i >= 0 && !made_[i]) {
      made_[i] = 1;
      missing_.push_back(i);
    }
  }
  ParallelFor(missing_.size(), kPointsPerBlock, [&](std::size_t begin, std::size_t end) {
    std::vector<Eigen::Vector3f> nn;
    for (std::size_t k = begin; k < end; ++k) {
      const int i = missing_[k];
      normals_[i] = NormalAt(cloud_[i], index_, radius_m_, viewpoint_, nn);
    }
  });
  made_count_ += missing_.size();
}

namespace {

// Point i's simplified point feature histogram (its row of `spfh`) and the neighbours it used.
void Spfh(const PointCloud& cloud, const Normals& normals, const VoxelHashIndex& index,
          float radius_m, int max_neighbors, int i, std::vector<int>& nn, std::vector<int>& kept,
          FeatureMatrix& spfh) {
  if (!normals[i].allFinite()) return;
  nn.clear();
  index.Radius(cloud[i], radius_m, nn);
  const int stride = std::max<int>(1, static_cast<int>(nn.size()) / max_neighbors);
  kept.reserve((nn.size() + stride - 1) / stride);  // one allocation, not a vector's doublings
  for (std::size_t k = 0; k < nn.size(); k += stride) {
    if (nn[k] != i && normals[nn[k]].allFinite()) kept.push_back(nn[k]);
  }
  if (kept.empty()) return;
  const float incr = 100.0f / static_cast<float>(kept.size());
  for (int j : kept) {
    int b1, b2, b3;
    if (!PairFeatureBins(cloud[i], normals[i], cloud[j], normals[j], b1, b2, b3)) continue;
    spfh(i, b1) += incr;
    spfh(i, kBins + b2) += incr;
    spfh(i, 2 * kBins + b3) += incr;
  }
}

}  // namespace

FeatureMatrix ComputeFpfh(const PointCloud& cloud, const Normals& normals,
                          const VoxelHashIndex& index, float radius_m, int max_neighbors,
                          const std::vector<int>& keypoints) {
  const int n = static_cast<int>(cloud.size());
  std::vector<std::vector<int>> neighbors(n);
  FeatureMatrix spfh = FeatureMatrix::Zero(n, 3 * kBins);
  ParallelFor(cloud.size(), kPointsPerBlock, [&](std::size_t begin, std::size_t end) {
    std::vector<int> nn;
    for (std::size_t i = begin; i < end; ++i) {
      Spfh(cloud, normals, index, radius_m, max_neighbors, static_cast<int>(i), nn, neighbors[i],
           spfh);
    }
  });
  FeatureMatrix fpfh = FeatureMatrix::Zero(static_cast<int>(keypoints.size()), 3 * kBins);
  ParallelFor(keypoints.size(), kPointsPerBlock, [&](std::size_t begin, std::size_t end) {
    for (std::size_t row = begin; row < end; ++row) {  // own SPFH + neighbours' by 1 / d
      const int i = keypoints[row];
      if (neighbors[i].empty()) continue;
      Eigen::RowVectorXf h = spfh.row(i);
      for (int j : neighbors[i]) {
        const float d = (cloud[j] - cloud[i]).norm();
        if (d > 0) h += spfh.row(j) / (d * static_cast<float>(neighbors[i].size()));
      }
      for (int s = 0; s < 3; ++s) {
        const float sum = h.segment(s * kBins, kBins).sum();
        if (sum > 0) h.segment(s * kBins, kBins) *= 100.0f / sum;
      }
      fpfh.row(static_cast<int>(row)) = h;
    }
  });
  return fpfh;
}

std::vector<Correspondence> MatchFeatures(const FeatureMatrix& source,
                                          const FeatureMatrix& target) {
  const int ns = static_cast<int>(source.rows()), nt = static_cast<int>(target.rows());
  if (ns == 0 || nt == 0) return {};  // a side without keypoints (NARF found none) matches nothing
  std::vector<int> best_t(ns, -1), best_s(nt, -1);
  std::vector<float> best_t_d(ns, std::numeric_limits<float>::max());
  std::vector<float> best_s_d(nt, std::numeric_limits<float>::max());
  // Rows of zeros (no histogram) match nothing: their |t|^2 is +inf below, so no distance to them
  // is below the FLT_MAX every best starts at.
  const Eigen::ArrayXf tn = target.rowwise().squaredNorm().array();
  const Eigen::ArrayXf tn_or_inf =
      (tn > 0).select(tn, Eigen::ArrayXf::Constant(nt, std::numeric_limits<float>::infinity()));
  const Eigen::VectorXf sn = source.rowwise().squaredNorm();
  // |s - t|^2 = |s|^2 + |t|^2 - 2 s.t, in blocks of source rows on the machine's cores. Each block
  // keeps the best source row of every target column it saw (the first of equals); merged in
  // block order below, the first of equals overall, as one loop over the rows finds. A row's
  // distances are whole arrays (Eigen vectorises them): its best column is the first holding
  // their minimum, each column's best row replaced where a row is strictly nearer.
  constexpr int kBlock = 256;
  const int blocks = (ns + kBlock - 1) / kBlock;
  std::vector<Eigen::ArrayXi> block_s(blocks);
  std::vector<Eigen::ArrayXf> block_s_d(blocks);
  using RowMajorXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  ParallelFor(blocks, 1, [&](std::size_t first, std::size_t last) {
    Eigen::ArrayXf dist(nt);
    for (std::size_t k = first; k < last; ++k) {
      const int b = static_cast<int>(k) * kBlock;
      const int rows = std::min(kBlock, ns - b);
      Eigen::ArrayXi& bs = block_s[k];
      Eigen::ArrayXf& bs_d = block_s_d[k];
      bs.setConstant(nt, -1);
      bs_d.setConstant(nt, std::numeric_limits<float>::max());
      const RowMajorXf d = -2.0f * source.middleRows(b, rows) * target.transpose();
      for (int r = 0; r < rows; ++r) {
        const int i = b + r;
        if (sn(i) <= 0) continue;
        dist = d.row(r).array().transpose() + sn(i) + tn_or_inf;
        const float nearest = dist.minCoeff();
        if (nearest < best_t_d[i]) {
          best_t_d[i] = nearest;
          best_t[i] = static_cast<int>(std::find(dist.data(), dist.data() + nt, nearest) - dist.data());
        }
        const auto nearer = dist < bs_d;
        bs = nearer.select(i, bs);
        bs_d = nearer.select(dist, bs_d);
      }
    }
  });
  for (int k = 0; k < blocks; ++k) {
    for (int j = 0; j < nt; ++j) {
      if (block_s_d[k][j] < best_s_d[j]) best_s_d[j] = block_s_d[k][j], best_s[j] = block_s[k][j];
    }
  }
  std::vector<Correspondence> corrs;
  for (int i = 0; i < ns; ++i) {
    if (best_t[i] >= 0 && best_s[best_t[i]] == i) corrs.push_back({i, best_t[i]});
  }
  return corrs;
}

SacResult SampleConsensus(const PointCloud& source, const PointCloud& target,
                          const std::vector<Correspondence>& corrs,
                          const RegistrationConfig& config,
                          const std::optional<PriorRegion>& region) {
  SacResult result;
  const int n = static_cast<int>(corrs.size());
  if (n < 3) return result;
  std::mt19937 rng(20120917);  // fixed: the same input gives the same output
  std::uniform_int_distribution<int> pick(0, n - 1);
  const float sim = static_cast<float>(config.sac_edge_similarity);
  const float min_edge = static_cast<float>(2.0 * config.feature_voxel_m);
  const float inlier_m = static_cast<float>(config.sac_inlier_m);
  const std::size_t keep = static_cast<std::size_t>(config.sac_hypotheses);
  // Hypotheses closer than ICP's capture range end in the same ICP minimum: one stands for all.
  // A rotation counts as distinct when it moves a point 5 m out (a typical range) that far.
  const PriorRegion same{Eigen::Isometry3d::Identity(), config.icp_max_distance_m,
                         config.icp_max_distance_m / 5.0};
  std::vector<SacHypothesis> top;  // best first
  auto offer = [&](const SacHypothesis& h) {
    auto near = std::find_if(top.begin(), top.end(), [&](const SacHypothesis& t) {
      return same.Contains(t.T_target_source.inverse() * h.T_target_source);
    });
    if (near != top.end()) {
      if (h.inliers <= near->inliers) return;
      top.erase(near);
    } else if (top.size() == keep && h.inliers <= top.back().inliers) {
      return;
    }
    top.insert(std::upper_bound(top.begin(), top.end(), h,
                                [](const SacHypothesis& a, const SacHypothesis& b) {
                                  return a.inliers > b.inliers;
                                }),
               h);
    if (top.size() > keep) top.pop_back();
  };
  long needed = config.sac_iterations;
  for (long it = 0; it < needed; ++it) {
    const int idx[3] = {pick(rng), pick(rng), pick(rng)};
    if (idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2]) continue;
    bool ok = true;
    for (int e = 0; e < 3 && ok; ++e) {  // prerejection: a rigid motion keeps edge lengths
      const Correspondence& a = corrs[idx[e]];
      const Correspondence& b = corrs[idx[(e + 1) % 3]];
      const float ls = (source[a.source] - source[b.source]).norm();
      const float lt = (target[a.target] - target[b.target]).norm();
      ok = std::min(ls, lt) >= sim * std::max(ls, lt) && ls >= min_edge;
    }
    if (!ok) continue;
    const std::vector<Correspondence> sample = {corrs[idx[0]], corrs[idx[1]], corrs[idx[2]]};
    const Eigen::Isometry3d T = FitRigid(source, target, sample);
    if (!T.matrix().allFinite() || (region && !region->Contains(T))) continue;
    const int inliers = CountInliers(source, target, corrs, T, inlier_m, nullptr);
    const int best_before = top.empty() ? 0 : top.front().inliers;
    offer({T, inliers});
    if (inliers <= best_before) continue;
    const double w = static_cast<double>(inliers) / n;  // adaptive stop at 99.9 % confidence
    const double k = std::log(1e-3) / std::log(std::max(1e-12, 1.0 - w * w * w));
    needed = std::min<long>(needed, static_cast<long>(it + 1 + 4 * k));
  }
  for (SacHypothesis& h : top) {
    for (int refit = 0; refit < 3; ++refit) {  // least squares on the inliers
      std::vector<Correspondence> inliers;
      CountInliers(source, target, corrs, h.T_target_source, inlier_m, &inliers);
      if (inliers.size() < 3) break;
      const Eigen::Isometry3d T = FitRigid(source, target, inliers);
      if (region && !region->Contains(T)) break;
      h.T_target_source = T;
      h.inliers = CountInliers(source, target, corrs, T, inlier_m, nullptr);
    }
  }
  if (top.empty()) return result;
  result.T_target_source = top.front().T_target_source;
  result.inliers = top.front().inliers;
  result.found = result.inliers >= config.sac_min_inliers;
  for (std::size_t i = 1; i < top.size(); ++i) {  // refits may have merged hypotheses
    const bool repeated = std::any_of(top.begin(), top.begin() + i, [&](const SacHypothesis& t) {
      return same.Contains(t.T_target_source.inverse() * top[i].T_target_source);
    });
    if (!repeated && top[i].inliers >= config.sac_min_inliers) {
      result.alternatives.push_back(top[i]);
    }
  }
  return result;
}

namespace {
// ICP's robust weights (iteratively reweighted least squares) and the cost a step must lower, of
// scale c = 2 cm at the robot's scale: above what correct pairs leave, the range noise (measured:
// 3.5 mm in the simulator, 2.6-2.8 mm on the real corridor pair) and a voxel centroid's departure
// from the target's tangent plane (inlier RMS at the true pose 1.1-1.9 cm in registration_eval,
// 1.5 cm on the real pair), so those keep (nearly) full weight. Huber's c is also at least a
// fifth of the gate. Cauchy (IcpKernel::kCauchy) lets a pair on another surface (an overlap's
// ragged edge, the far side of a pole) 5-10 cm off pull as c^2 / r rather than Huber's constant
// c: summed over a partial overlap those constant pulls moved the pose along weak directions
// (registration_eval urban pair 104: 4.4 cm / 0.31 deg off with Huber throughout; after the
// final refinement with Cauchy, registration.cpp, 0.8 cm / 0.07 deg).
class RobustKernel {
 public:
  RobustKernel(IcpKernel kind, double length_scale, double gate)
      : cauchy_(kind == IcpKernel::kCauchy),
        c_(cauchy_ ? kScale_m * length_scale : std::max(kScale_m * length_scale, gate / 5)) {}
  double Weight(double r) const {
    if (cauchy_) return 1.0 / (1.0 + (r / c_) * (r / c_));
    return std::fabs(r) <= c_ ? 1.0 : c_ / std::fabs(r);
  }
  // Huber: w r^2 (r^2 inside, c |r| outside); Cauchy: its rho, c^2 log(1 + (r / c)^2).
  double Cost(double r) const {
    if (cauchy_) return c_ * c_ * std::log1p((r / c_) * (r / c_));
    return Weight(r) * r * r;
  }

 private:
  static constexpr double kScale_m = 0.02;
  bool cauchy_;
  double c_;
};
}  // namespace

IcpResult PointToPlaneLm(const IcpTarget& target, const PointCloud& source,
                         const Eigen::Isometry3d& init, const RegistrationConfig& config,
                         const Weakness& frozen, IcpKernel kind) {
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  // The projector onto the free directions (frozen ones are orthonormal within their kind).
  Matrix6d keep = Matrix6d::Identity();
  for (const Eigen::Vector3d& a : frozen.rotation_axes) {
    keep.topLeftCorner<3, 3>() -= a * a.transpose();
  }
  for (const Eigen::Vector3d& d : frozen.translations) {
    keep.bottomRightCorner<3, 3>() -= d * d.transpose();
  }
  IcpResult result;
  result.T_target_source = init;
  double gate = config.icp_max_distance_m, lambda = 1e-4, prev_mean = -1;
  // The gate shrinks to icp_min_distance_m, then to the inlier band (registration_config.hpp).
  double gate_floor = config.icp_min_distance_m;
  const double band = InlierBand(config);
  std::vector<Pair> pairs;
  for (int iter = 0; iter < config.icp_max_iterations; ++iter) {
    FindPairs(target, source, result.T_target_source, static_cast<float>(gate), pairs);
    if (pairs.size() < 6) break;
    const RobustKernel kernel(kind, config.length_scale, gate);
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    double err = 0;
    for (const Pair& q : pairs) {  // r = n.(p - t); dr/d(omega) = p x n, dr/dv = n
      const double r = q.n.dot(q.p - q.t), w = kernel.Weight(r);
      Vector6d J;
      J << q.p.cross(q.n), q.n;
      H += w * J * J.transpose();
      g += w * J * r;
      err += kernel.Cost(r);
    }
    bool stepped = false;
    for (int tries = 0; tries < 8 && !stepped; ++tries) {  // Levenberg-Marquardt damping
      Matrix6d A = H;
      A.diagonal() += lambda * H.diagonal();
      // The step minimises over the free directions only: keep A keep + (I - keep) is A on them
      // and the identity on the frozen ones, whose part of the step is then 0. Solving for all six
      // and projecting the frozen part away is not that step where a frozen direction is coupled
      // to free ones (a slide along a curving gully and a turn about its bend): ICP crept along
      // the coupled mode, 32-40 iterations of icp_max_iterations' 40 where this takes 10
      // (FrozenIcp test), and in the gully's missions ended off the best fit (benchmarks/README.md,
      // session 43).
      if (frozen.any()) A = keep * A * keep + (Matrix6d::Identity() - keep);
      const Vector6d delta = A.ldlt().solve(-(keep * g));
      const Eigen::Isometry3d D = Exp(delta);
      double new_err = 0;
      for (const Pair& q : pairs) new_err += kernel.Cost(q.n.dot(D * q.p - q.t));
      if (new_err <= err) {
        result.T_target_source = D * result.T_target_source;
        lambda = std::max(1e-7, lambda / 10);
        stepped = true;
      } else {
        lambda *= 10;
      }
    }
    ++result.iterations;
    const double mean = err / static_cast<double>(pairs.size());
    const bool at_floor = gate <= gate_floor + 1e-9;
    if (at_floor && prev_mean >= 0 &&
        (!stepped ||
         std::fabs(prev_mean - mean) <= config.icp_epsilon * std::max(prev_mean, 1e-12))) {
      if (gate_floor <= band + 1e-9) break;  // Algorithm 1: error change below epsilon
      gate_floor = band, gate = band, prev_mean = -1;  // converged: on at the inlier band
      continue;
    }
    prev_mean = at_floor ? mean : -1;
    gate = std::max(gate_floor, gate * 0.7);
  }
  const IcpResult score = Evaluate(target, source, result.T_target_source, config);
  result.rmse_m = score.rmse_m;
  result.fitness_m2 = score.fitness_m2;
  result.inlier_ratio = score.inlier_ratio;
  result.degeneracy = score.degeneracy;
  result.hessian = score.hessian;
  result.inliers = score.inliers;
  return result;
}

namespace {
// Scores of `T` over the inlier pairs, and the translation (sum n n^T) and rotation (sum of
// (p - centroid) x n, outer product) constraint matrices.
std::pair<Eigen::Matrix3d, Eigen::Matrix3d> ScorePairs(const IcpTarget& target,
                                                       const PointCloud& source,
                                                       const Eigen::Isometry3d& T,
                                                       const RegistrationConfig& config,
                                                       IcpResult& out) {
  std::vector<Pair> pairs;
  FindPairs(target, source, T, static_cast<float>(config.inlier_distance_m), pairs);
  Eigen::Matrix3d Ct = Eigen::Matrix3d::Zero(), Cr = Eigen::Matrix3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Pair& q : pairs) centroid += q.p;
  if (!pairs.empty()) centroid /= static_cast<double>(pairs.size());
  double sq_plane = 0, sq_point = 0;
  out.hessian.setZero();
  for (const Pair& q : pairs) {
    Eigen::Matrix<double, 6, 1> J;
    J << q.p.cross(q.n), q.n;
    out.hessian += J * J.transpose();
    const double r = q.n.dot(q.p - q.t);
    sq_plane += r * r;
    sq_point += (q.p - q.t).squaredNorm();
    Ct += q.n * q.n.transpose();
    const Eigen::Vector3d m = (q.p - centroid).cross(q.n);
    Cr += m * m.transpose();
  }
  out.T_target_source = T;
  out.inliers = static_cast<int>(pairs.size());
  out.inlier_ratio = source.empty() ? 0.0 : static_cast<double>(pairs.size()) / source.size();
  out.rmse_m = pairs.empty() ? 0.0 : std::sqrt(sq_plane / pairs.size());
  out.fitness_m2 = pairs.empty() ? 0.0 : sq_point / pairs.size();
  return {Ct, Cr};
}

// Weakest / strongest eigenvalue of C.
double WeakestRatio(const Eigen::Matrix3d& C) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
  const double max_ev = eig.eigenvalues()(2);
  return max_ev > 0 ? eig.eigenvalues()(0) / max_ev : 0.0;
}

// Eigenvectors of C whose eigenvalue is below ratio x the largest, at most `max`, weakest first,
// appended to `out` with their ratios.
void WeakEigenvectors(const Eigen::Matrix3d& C, double ratio, int max,
                      std::vector<Eigen::Vector3d>& out, std::vector<double>& ratios) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
  const double max_ev = eig.eigenvalues()(2);
  for (int k = 0; k < 2 && k < max; ++k) {
    const double r = max_ev > 0 ? eig.eigenvalues()(k) / max_ev : 0.0;
    if (r >= ratio) break;
    out.push_back(eig.eigenvectors().col(k));
    ratios.push_back(r);
  }
}
}  // namespace

IcpResult Evaluate(const IcpTarget& target, const PointCloud& source, const Eigen::Isometry3d& T,
                   const RegistrationConfig& config) {
  IcpResult out;
  const auto [Ct, Cr] = ScorePairs(target, source, T, config, out);
  out.degeneracy = std::min(WeakestRatio(Ct), WeakestRatio(Cr));
  return out;
}

Weakness WeakDirections(const IcpTarget& target, const PointCloud& source,
                        const Eigen::Isometry3d& T, const RegistrationConfig& config, double ratio,
                        int max_per_kind) {
  IcpResult unused;
  const auto [Ct, Cr] = ScorePairs(target, source, T, config, unused);
  Weakness out;
  WeakEigenvectors(Ct, ratio, max_per_kind, out.translations, out.translation_ratios);
  WeakEigenvectors(Cr, ratio, max_per_kind, out.rotation_axes, out.rotation_ratios);
  return out;
}

std::vector<int> EvenIndices(std::size_t size, int max_points) {
  const int n = std::min<int>(static_cast<int>(size), max_points);
  std::vector<int> out(n);
  const double step = static_cast<double>(size) / n;
  for (int i = 0; i < n; ++i) out[i] = static_cast<int>(i * step);
  return out;
}

PointCloud EvenSubsample(const PointCloud& cloud, int max_points) {
  PointCloud out;
  for (int i : EvenIndices(cloud.size(), max_points)) out.push_back(cloud[i]);
  return out;
}

}  // namespace pitchlab::mapping
