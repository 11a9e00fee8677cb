#include "pitchlab/mapping/registration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "fast_pipeline.hpp"
#include "pcl_pipeline.hpp"

namespace pitchlab::mapping {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kMinPoints = 30;  // after the voxel grid, per cloud
// Normals are oriented towards the sensor: roughly above base_link's origin [m].
const Eigen::Vector3f kViewpoint(0.1f, 0.0f, 0.55f);

class Stopwatch {
 public:
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

Result<void> CheckCloud(const PointCloud& cloud, const char* name) {
  if (cloud.empty())
    return Fail(Error::Code::kInvalidArgument, std::string(name) + " cloud is empty");
  std::size_t bad = 0;
  for (const Eigen::Vector3f& p : cloud) bad += p.allFinite() ? 0 : 1;
  if (bad > 0) {
    return Fail(Error::Code::kInvalidArgument,
                std::string(name) + " cloud has " + std::to_string(bad) + " of " +
                    std::to_string(cloud.size()) + " points that are not finite (NaN/inf)");
  }
  return {};
}

std::string Percent(double ratio) {
  std::ostringstream os;
  os.precision(3);
  os << 100.0 * ratio << " %";
  return os.str();
}

// Why `icp` may not be merged, or empty when it may.
std::string Rejection(const IcpResult& icp, const RegistrationPrior& prior,
                      const RegistrationConfig& config) {
  std::ostringstream os;
  os.precision(3);
  if (icp.inlier_ratio < config.min_inlier_ratio) {
    os << "only " << Percent(icp.inlier_ratio) << " of source points within "
       << config.inlier_distance_m << " m of the target (min " << Percent(config.min_inlier_ratio)
       << "): no overlap or misaligned";
  } else if (icp.rmse_m > config.max_rmse_m) {
    os << "inlier RMS error " << icp.rmse_m << " m > max_rmse_m " << config.max_rmse_m;
  } else if (prior.odometry || prior.previous_motion) {
    const PoseError d = ComparePoses(icp.T_target_source,
                                     prior.odometry ? *prior.odometry : *prior.previous_motion);
    if (d.translation_m > config.constraint_translation_m ||
        d.rotation_deg > config.constraint_rotation_deg) {
      os << "geometric constraint: result is " << d.translation_m << " m / " << d.rotation_deg
         << " deg from the " << (prior.odometry ? "odometry prior" : "constant-velocity motion")
         << " (limit " << config.constraint_translation_m << " m / "
         << config.constraint_rotation_deg << " deg)";
    }
  }
  return os.str();
}

// The clouds after the voxel grid, with what ICP needs of the target.
struct Prepared {
  PointCloud target_icp, source_icp, target_features, source_features;
  Normals target_normals;
};

// The directions along which the solution is not unique: ICP restarted degeneracy_probe_m along
// the weakest translation (degeneracy_probe_deg about the weakest rotation axis) does not come
// back (a corridor; an open plane). Empty when well constrained.
Weakness DegenerateDirections(const IcpTarget& target, const PointCloud& source,
                              const IcpResult& at, const RegistrationConfig& config) {
  Weakness out;
  if (at.degeneracy >= config.degeneracy_ratio) return out;
  const Weakness weak = WeakDirections(target, source, at.T_target_source, config);
  if (weak.translation) {
    const Eigen::Isometry3d start =
        Eigen::Translation3d(config.degeneracy_probe_m * *weak.translation) * at.T_target_source;
    const IcpResult probe = PointToPlaneLm(target, source, start, config, {});
    const double back_m = ComparePoses(probe.T_target_source, at.T_target_source).translation_m;
    if (back_m >= 0.25 * config.degeneracy_probe_m) out.translation = weak.translation;
  }
  if (weak.rotation_axis) {
    const Eigen::Vector3d c = at.T_target_source.translation();
    const Eigen::Isometry3d turn =
        Eigen::Translation3d(c) *
        Eigen::AngleAxisd(config.degeneracy_probe_deg * kPi / 180.0, *weak.rotation_axis) *
        Eigen::Translation3d(-c);
    const IcpResult probe = PointToPlaneLm(target, source, turn * at.T_target_source, config, {});
    const double back_deg = ComparePoses(probe.T_target_source, at.T_target_source).rotation_deg;
    if (back_deg >= 0.25 * config.degeneracy_probe_deg) out.rotation_axis = weak.rotation_axis;
  }
  return out;
}

// ICP from `init` with the configured backend; in degenerate geometry (`freeze_weak`) the weak
// translation direction keeps the initial guess (constant velocity / odometry carries it).
IcpResult RunIcp(const PointCloud& source, const IcpTarget& target, const Prepared& prep,
                 const Eigen::Isometry3d& init, const RegistrationConfig& config, bool freeze_weak,
                 bool* degenerate) {
  if (config.backend == RegistrationBackend::kPcl) {
    // PCL's pipeline aligns the whole voxelized source (no subsampling).
    const PclIcp pcl = PclIcpNonLinear(prep.target_icp, prep.source_icp, init, config);
    IcpResult r = Evaluate(target, source, pcl.T_target_source, config);
    r.iterations = pcl.iterations;
    return r;
  }
  IcpResult r = PointToPlaneLm(target, source, init, config, {});
  const Weakness weak = DegenerateDirections(target, source, r, config);
  if (degenerate) *degenerate = weak.any();
  if (freeze_weak && weak.any()) {
    const int first = r.iterations;
    r = PointToPlaneLm(target, source, init, config, weak);
    r.iterations += first;
  }
  return r;
}

// NARF on the dense scans (range images need one return per beam) + the same RANSAC.
SacResult FastNarfAlignment(const PointCloud& target, const PointCloud& source,
                            const RegistrationConfig& config,
                            const std::optional<PriorRegion>& region, StageTimings& timings) {
  Stopwatch lap;
  const NarfFeatures t = ComputeNarf(target, config), s = ComputeNarf(source, config);
  timings.features_s += lap.Lap();
  const SacResult sac = SampleConsensus(
      s.keypoints, t.keypoints, MatchFeatures(s.descriptors, t.descriptors), config, region);
  timings.initial_alignment_s += lap.Lap();
  return sac;
}

// Our FPFH + RANSAC initial alignment. When it finds nothing at the configured scale (a confined
// scene: under a desk, between crates), it retries once at half the scale (voxel, radii, inlier
// distance).
SacResult FastFeatureAlignment(const Prepared& prep, const RegistrationConfig& config,
                               const std::optional<PriorRegion>& region, StageTimings& timings) {
  SacResult sac;
  for (const double scale : {1.0, 0.5}) {
    Stopwatch lap;
    RegistrationConfig c = config;
    c.feature_voxel_m *= scale;
    c.normal_radius_m *= scale;
    c.feature_radius_m *= scale;
    c.sac_inlier_m *= scale;
    const PointCloud target =
        scale == 1.0 ? prep.target_features : VoxelDownsample(prep.target_icp, c.feature_voxel_m);
    const PointCloud source =
        scale == 1.0 ? prep.source_features : VoxelDownsample(prep.source_icp, c.feature_voxel_m);
    timings.voxel_s += lap.Lap();
    const float r_normal = static_cast<float>(c.normal_radius_m);
    const float r_feature = static_cast<float>(c.feature_radius_m);
    const VoxelHashIndex t_index(target, std::max(r_normal, r_feature));
    const VoxelHashIndex s_index(source, std::max(r_normal, r_feature));
    const Normals tn = EstimateNormals(target, t_index, r_normal, kViewpoint);
    const Normals sn = EstimateNormals(source, s_index, r_normal, kViewpoint);
    timings.normals_s += lap.Lap();
    const std::vector<int> tk = EvenIndices(target.size(), c.max_feature_points);
    const std::vector<int> sk = EvenIndices(source.size(), c.max_feature_points);
    const FeatureMatrix tf = ComputeFpfh(target, tn, t_index, r_feature, c.max_neighbors, tk);
    const FeatureMatrix sf = ComputeFpfh(source, sn, s_index, r_feature, c.max_neighbors, sk);
    timings.features_s += lap.Lap();
    const std::vector<Correspondence> corrs = MatchFeatures(sf, tf);
    PointCloud t_key, s_key;
    for (int i : tk) t_key.push_back(target[i]);
    for (int i : sk) s_key.push_back(source[i]);
    sac = SampleConsensus(s_key, t_key, corrs, c, region);
    timings.initial_alignment_s += lap.Lap();
    if (sac.found) break;
  }
  return sac;
}

// The winner of the hypothesis verification and where its start came from.
struct Verified {
  IcpResult icp;
  RegistrationPath path = RegistrationPath::kFeatures;
  int iterations = 0;  // of all the ICP runs
  std::string note;    // why a runner-up, the prior's guess or a search won, else empty
};

// Short ICP runs (8 iterations on 300 evenly sampled source points, a tenth of a full run) from
// each start: screens many starts cheaply; the promising ones are refined with the full ICP.
std::vector<IcpResult> Screen(const IcpTarget& target, const PointCloud& source,
                              const std::vector<Eigen::Isometry3d>& starts,
                              const RegistrationConfig& config, int& iterations) {
  RegistrationConfig screen = config;
  screen.icp_max_iterations = 8;
  const PointCloud few = EvenSubsample(source, 300);
  std::vector<IcpResult> out;
  for (const Eigen::Isometry3d& start : starts) {
    out.push_back(PointToPlaneLm(target, few, start, screen, {}));
    iterations += out.back().iterations;
  }
  return out;
}

// Two poses in the same ICP minimum (closer than half its capture range).
bool SamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
              const RegistrationConfig& config) {
  const PoseError d = ComparePoses(a, b);
  return d.translation_m < 0.5 * config.icp_max_distance_m && d.rotation_deg < 2.0;
}

// A start to verify and what to call it.
struct Start {
  Eigen::Isometry3d T;
  RegistrationPath path;
  std::string name;
};

// The 3 x 3 x 3 grid over the guess's uncertainty (guess_search_m, guess_search_deg about the
// vertical): neighbours lie guess_search_m apart, so every pose of the region is within ICP's
// capture range of one (0.6 m spacing, 0.5 m gate; a 12 deg turn moves a point 5 m out 0.5 m).
std::vector<Start> GuessGrid(const Start& guess, const RegistrationConfig& config) {
  std::vector<Start> out;
  for (int ix = -1; ix <= 1; ++ix) {
    for (int iy = -1; iy <= 1; ++iy) {
      for (int iyaw = -1; iyaw <= 1; ++iyaw) {
        if (ix == 0 && iy == 0 && iyaw == 0) continue;  // the guess itself
        out.push_back(
            {guess.T * PoseFromXyzRpyDeg(ix * config.guess_search_m, iy * config.guess_search_m, 0,
                                         0, 0, iyaw * config.guess_search_deg),
             guess.path, "a grid of starts around " + guess.name});
      }
    }
  }
  return out;
}

// ICP from each hypothesis of the consensus (best first, then the runners-up) and from the prior's
// guess (odometry, else the constant-velocity motion): the best fit (inlier ratio) that passes the
// acceptance test wins; a start that ends in the pose already held does not count. The consensus
// scores a pose by a few dozen sparse feature matches; in repeated structure (desk rows, a hall)
// a pose one unit off collects as many, while ICP's inliers over thousands of points tell them
// apart. The other starts are screened (short ICP) and only the two best screened refined. Two
// searches widen the net:
// - the consensus is weak (fewer than twice sac_min_inliers agree) and the guess ends elsewhere:
//   a grid of starts over the guess's uncertainty, as ICP from the guess alone may stop in a local
//   minimum short of the true pose;
// - the winner is weakly constrained along a direction (degeneracy_ratio: a hall, a street): starts
//   along it every half capture range up to degeneracy_search_m, for the repeated unit the
//   features may have matched instead.
// Neither decides degeneracy: the caller still probes the winner (a bare corridor stays ambiguous
// whichever window coincidence scores best). When no start passes, the consensus' best is returned
// (its rejection is then reported).
Verified VerifyHypotheses(const PointCloud& source, const IcpTarget& target, const SacResult& sac,
                          const RegistrationPrior& prior, const RegistrationConfig& config) {
  Verified best;
  best.icp = PointToPlaneLm(target, source, sac.T_target_source, config, {});
  best.iterations = best.icp.iterations;
  bool accepted = Rejection(best.icp, prior, config).empty();
  auto offer = [&](const IcpResult& icp, const Start& from) {
    if (SamePose(icp.T_target_source, best.icp.T_target_source, config)) return;
    if (!Rejection(icp, prior, config).empty()) return;
    if (accepted && icp.inlier_ratio <= best.icp.inlier_ratio) return;
    std::ostringstream os;
    os.precision(3);
    os << "ICP from " << from.name << " fits best (" << Percent(icp.inlier_ratio) << " inliers vs "
       << Percent(best.icp.inlier_ratio) << ")";
    best.note = os.str();
    best.icp = icp;
    best.path = from.path;
    accepted = true;
  };
  // Screens `starts`, refines the `refine` best-screened that end away from the pose held.
  auto verify = [&](const std::vector<Start>& starts, std::size_t refine) {
    std::vector<Eigen::Isometry3d> poses;
    for (const Start& s : starts) poses.push_back(s.T);
    const std::vector<IcpResult> screened = Screen(target, source, poses, config, best.iterations);
    std::vector<std::size_t> order(starts.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return screened[a].inlier_ratio > screened[b].inlier_ratio;
    });
    std::vector<Eigen::Isometry3d> refined;
    for (const std::size_t i : order) {
      if (refined.size() == refine) break;
      const Eigen::Isometry3d& end = screened[i].T_target_source;
      if (SamePose(end, best.icp.T_target_source, config)) continue;
      if (std::any_of(refined.begin(), refined.end(),
                      [&](const auto& r) { return SamePose(end, r, config); })) {
        continue;
      }
      refined.push_back(end);
      const IcpResult icp = PointToPlaneLm(target, source, end, config, {});
      best.iterations += icp.iterations;
      offer(icp, starts[i]);
    }
    return screened;
  };
  std::vector<Start> starts;
  for (std::size_t i = 0; i < sac.alternatives.size(); ++i) {
    starts.push_back({sac.alternatives[i].T_target_source, RegistrationPath::kFeatures,
                      "runner-up hypothesis " + std::to_string(i + 1) + " of the consensus"});
  }
  std::optional<Start> guess;
  if (prior.odometry) {
    guess = Start{*prior.odometry, RegistrationPath::kOdometry, "the odometry guess"};
  } else if (prior.previous_motion && config.constant_velocity_fallback) {
    guess = Start{*prior.previous_motion, RegistrationPath::kFallback, "the fallback guess"};
  }
  if (guess) starts.push_back(*guess);
  const std::vector<IcpResult> screened = verify(starts, 2);
  if (guess && config.guess_search_m > 0 && sac.inliers < 2 * config.sac_min_inliers &&
      !SamePose(screened.back().T_target_source, best.icp.T_target_source, config)) {
    verify(GuessGrid(*guess, config), 2);
  }
  if (best.icp.degeneracy < config.degeneracy_ratio && config.degeneracy_search_m > 0) {
    const Weakness weak = WeakDirections(target, source, best.icp.T_target_source, config);
    if (weak.translation) {
      const double step = 0.5 * config.icp_max_distance_m;
      const int steps = static_cast<int>(std::ceil(config.degeneracy_search_m / step));
      std::vector<Start> along;
      for (int k = -steps; k <= steps; ++k) {
        if (k == 0) continue;
        along.push_back(
            {Eigen::Translation3d(k * step * *weak.translation) * best.icp.T_target_source,
             best.path, "starts along the weakly constrained direction"});
      }
      verify(along, 2);
    }
  }
  return best;
}

// ICP from the guess was rejected (a confined scene: under desks, between crates, where the guess
// lies outside ICP's basin): the grid over the guess's uncertainty, screened, the two best refined;
// the best-fitting accepted result, if any.
std::optional<IcpResult> SearchAroundGuess(const IcpTarget& target, const PointCloud& source,
                                           const Start& guess, const RegistrationPrior& prior,
                                           const RegistrationConfig& config, int& iterations) {
  std::vector<Eigen::Isometry3d> poses;
  for (const Start& s : GuessGrid(guess, config)) poses.push_back(s.T);
  std::vector<IcpResult> screened = Screen(target, source, poses, config, iterations);
  std::stable_sort(screened.begin(), screened.end(),
                   [](const auto& a, const auto& b) { return a.inlier_ratio > b.inlier_ratio; });
  std::optional<IcpResult> best;
  for (std::size_t i = 0; i < std::min<std::size_t>(2, screened.size()); ++i) {
    const IcpResult icp = PointToPlaneLm(target, source, screened[i].T_target_source, config, {});
    iterations += icp.iterations;
    if (Rejection(icp, prior, config).empty() && (!best || icp.inlier_ratio > best->inlier_ratio)) {
      best = icp;
    }
  }
  return best;
}

void Fill(RegistrationResult& out, const IcpResult& icp, RegistrationPath path) {
  out.T_target_source = icp.T_target_source;
  out.path = path;
  out.fitness_m2 = icp.fitness_m2;
  out.rmse_m = icp.rmse_m;
  out.inlier_ratio = icp.inlier_ratio;
  out.degeneracy = icp.degeneracy;
  out.iterations += icp.iterations;
}

}  // namespace

const char* ToString(RegistrationPath path) {
  switch (path) {
    case RegistrationPath::kFeatures:
      return "features";
    case RegistrationPath::kOdometry:
      return "odometry";
    case RegistrationPath::kFallback:
      return "fallback";
  }
  return "?";
}

PoseError ComparePoses(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d d = truth.inverse() * estimate;
  return {Eigen::AngleAxisd(d.linear()).angle() * 180.0 / kPi, d.translation().norm()};
}

Eigen::Isometry3d PoseFromXyzRpyDeg(double x, double y, double z, double roll_deg, double pitch_deg,
                                    double yaw_deg) {
  const double k = kPi / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * k, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch_deg * k, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll_deg * k, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

Result<RegistrationResult> Register(const PointCloud& target, const PointCloud& source,
                                    const RegistrationPrior& prior,
                                    const RegistrationConfig& config) {
  try {
    config.Validate();
  } catch (const std::invalid_argument& e) {
    return Fail(Error::Code::kInvalidArgument, e.what());
  }
  if (auto ok = CheckCloud(target, "target"); !ok) return tl::make_unexpected(ok.error());
  if (auto ok = CheckCloud(source, "source"); !ok) return tl::make_unexpected(ok.error());

  RegistrationResult out;
  Stopwatch total, lap;
  // 1. Voxel grid.
  Prepared prep;
  prep.target_icp = VoxelDownsample(target, config.icp_voxel_m);
  prep.source_icp = VoxelDownsample(source, config.icp_voxel_m);
  prep.target_features = VoxelDownsample(prep.target_icp, config.feature_voxel_m);
  prep.source_features = VoxelDownsample(prep.source_icp, config.feature_voxel_m);
  out.timings.voxel_s = lap.Lap();
  for (const auto& [cloud, name] :
       {std::pair{&prep.target_icp, "target"}, {&prep.source_icp, "source"}}) {
    if (cloud->size() < kMinPoints) {
      return Fail(Error::Code::kInvalidArgument,
                  std::string(name) + " cloud has " + std::to_string(cloud->size()) +
                      " points after the " + std::to_string(config.icp_voxel_m) +
                      " m voxel grid; registration needs at least " + std::to_string(kMinPoints));
    }
  }
  // 2. Normals of the ICP target (the feature clouds' normals are part of the feature stage).
  const float fine_cell = static_cast<float>(
      std::max({config.icp_min_distance_m, config.inlier_distance_m, config.icp_normal_radius_m}));
  const VoxelHashIndex fine(prep.target_icp, fine_cell);
  const VoxelHashIndex coarse(prep.target_icp,
                              std::max<double>(fine_cell, config.icp_max_distance_m));
  prep.target_normals = EstimateNormals(prep.target_icp, fine,
                                        static_cast<float>(config.icp_normal_radius_m), kViewpoint);
  out.timings.normals_s = lap.Lap();
  const IcpTarget icp_target{prep.target_icp, prep.target_normals, coarse, fine, fine_cell};
  const PointCloud icp_source = EvenSubsample(prep.source_icp, config.icp_max_points);

  // Geometric constraint: around the odometry prior, else around the constant-velocity motion.
  std::optional<PriorRegion> region;
  if (const auto& centre = prior.odometry ? prior.odometry : prior.previous_motion; centre) {
    region = PriorRegion{*centre, config.constraint_translation_m,
                         config.constraint_rotation_deg * kPi / 180.0};
  }
  std::vector<std::string> notes;
  bool ambiguous = false;
  // 3-4. Features and sample-consensus initial alignment.
  if (config.features != FeatureKind::kNone) {
    SacResult sac;
    if (config.backend == RegistrationBackend::kPcl) {
      const PclAlignment pcl =
          PclInitialAlignment(prep.target_features, prep.source_features, target, source, config);
      out.timings.normals_s += pcl.normals_s;
      out.timings.features_s = pcl.features_s;
      out.timings.initial_alignment_s = pcl.sac_s;
      sac = SacResult{};  // PCL's SAC-IA gives one pose, no runners-up
      sac.found = pcl.found && (!region || region->Contains(pcl.T_target_source));
      sac.T_target_source = pcl.T_target_source;
      sac.inliers = pcl.correspondences;
      lap.Lap();
    } else if (config.features == FeatureKind::kNarf) {
      sac = FastNarfAlignment(target, source, config, region, out.timings);
      lap.Lap();
    } else {
      sac = FastFeatureAlignment(prep, config, region, out.timings);
      lap.Lap();
    }
    out.sac_inliers = sac.inliers;
    if (sac.found) {
      IcpResult icp;
      RegistrationPath path = RegistrationPath::kFeatures;
      std::string note;
      if (config.backend == RegistrationBackend::kPcl) {
        icp = RunIcp(icp_source, icp_target, prep, sac.T_target_source, config, false, &ambiguous);
      } else {
        const Verified v = VerifyHypotheses(icp_source, icp_target, sac, prior, config);
        icp = v.icp, path = v.path, note = v.note;
        out.iterations += v.iterations - icp.iterations;  // Fill adds the winner's own
        ambiguous = DegenerateDirections(icp_target, icp_source, icp, config).any();
      }
      out.timings.icp_s += lap.Lap();
      Fill(out, icp, path);
      const std::string rejection = Rejection(icp, prior, config);
      if (!ambiguous && rejection.empty()) {
        out.success = true;
        out.reason = note.empty() ? std::string(ToString(path)) : note;
        out.timings.total_s = total.Lap();
        return out;
      }
      std::ostringstream os;
      os.precision(3);
      if (ambiguous) {
        os << "feature alignment ambiguous: degenerate geometry (ICP restarted "
           << config.degeneracy_probe_m << " m / " << config.degeneracy_probe_deg
           << " deg along the weakest direction does not come back)";
      } else {
        os << "feature alignment rejected: " << rejection;
      }
      notes.push_back(os.str());
    } else {
      notes.push_back("initial alignment failed: " + std::to_string(sac.inliers) +
                      " agreeing feature correspondences (min " +
                      std::to_string(config.sac_min_inliers) + ")" +
                      (region ? " inside the prior's region" : ""));
    }
  }
  // 5. Non-linear ICP from the odometry prior, then from the constant-velocity motion.
  std::vector<std::pair<RegistrationPath, Eigen::Isometry3d>> guesses;
  if (prior.odometry) guesses.emplace_back(RegistrationPath::kOdometry, *prior.odometry);
  if (prior.previous_motion && config.constant_velocity_fallback) {
    guesses.emplace_back(RegistrationPath::kFallback, *prior.previous_motion);
  }
  for (const auto& [path, guess] : guesses) {
    bool degenerate = false;
    IcpResult icp = RunIcp(icp_source, icp_target, prep, guess, config, true, &degenerate);
    std::string rejection = Rejection(icp, prior, config);
    bool searched = false;
    if (!rejection.empty() && config.backend == RegistrationBackend::kFast &&
        config.guess_search_m > 0) {
      int iterations = 0;
      const std::optional<IcpResult> found = SearchAroundGuess(
          icp_target, icp_source, {guess, path, ToString(path)}, prior, config, iterations);
      out.iterations += iterations;
      // Only a pose the scene pins down may replace the guess: in a corridor a grid start fits
      // anywhere along the axis, and nothing says where.
      if (found && !DegenerateDirections(icp_target, icp_source, *found, config).any()) {
        notes.push_back(std::string("ICP from the ") + ToString(path) + " guess: " + rejection);
        icp = *found, rejection.clear(), searched = true, degenerate = false;
        out.iterations -= icp.iterations;  // Fill adds the winner's own
      } else if (found) {
        rejection +=
            " (a grid of starts around the guess fits, but degenerate geometry leaves the "
            "pose undetermined there)";
      }
    }
    out.timings.icp_s += lap.Lap();
    Fill(out, icp, path);
    if (rejection.empty()) {
      out.success = true;
      notes.push_back(
          std::string("took the ") + ToString(path) + " path" +
          (degenerate ? " (degenerate: the weak directions kept from the guess)" : "") +
          (searched ? " (ICP from the best of a grid of starts around the guess)" : ""));
      break;
    }
    notes.push_back(std::string(ToString(path)) + " path rejected: " + rejection);
  }
  if (!out.success && guesses.empty()) {
    notes.push_back("no odometry prior or previous motion to fall back on");
  }
  for (std::size_t i = 0; i < notes.size(); ++i) out.reason += (i ? "; " : "") + notes[i];
  out.timings.total_s = total.Lap();
  return out;
}

}  // namespace pitchlab::mapping
