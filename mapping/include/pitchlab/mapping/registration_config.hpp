#pragma once
// Settings of the registration pipeline (Algorithm 1), one plain aggregate loadable from the YAML
// section `registration:`. Lengths in metres, angles in degrees (user boundary), as named.

#include <limits>
#include <string>

#include "pitchlab/mapping/cloud_statistics.hpp"

namespace pitchlab::mapping {

/// The value of a setting left to the data (`auto` in YAML): Register() derives it from what the
/// clouds measure (RegistrationConfig::Resolve) and reports the value it used.
inline constexpr double kAuto = std::numeric_limits<double>::quiet_NaN();

/// Which implementation runs the feature, initial-alignment and ICP stages.
enum class RegistrationBackend {
  kFast,  ///< ours: hashed voxels, own FPFH, correspondence RANSAC, point-to-plane LM (default)
  kPcl,   ///< PCL's NormalEstimation, FPFHEstimation/NARF, SampleConsensusInitialAlignment, ICP-NL
};

/// Descriptor used for the sample-consensus initial alignment (the paper's Table 1).
enum class FeatureKind {
  kFpfh,  ///< Fast Point Feature Histograms (33 bins)
  kNarf,  ///< Normal-Aligned Radial Features on range images of the dense scans (PCL's NARF)
  kNone,  ///< no feature alignment: ICP starts from the odometry prior / constant velocity
};

/// Every knob of Register(); defaults suit a 72k-point LMS200 scan indoors and outdoors.
///
/// Lengths [m] are given for a ground robot's laser scan (an LMS200's: noise about 3 mm) and
/// multiplied by `length_scale`, which `auto` derives from the data: a scene an order of
/// magnitude smaller or larger (an object on a turntable, a scaled model) scales every length
/// with it. The acceptance gates left `auto` follow the measured noise (mapping/README.md).
struct RegistrationConfig {
  RegistrationBackend backend = RegistrationBackend::kFast;
  FeatureKind features = FeatureKind::kFpfh;

  /// Multiplies every length setting below [1]. auto: 10^round(log10(sqrt(n / 3.4 mm x R / 2 m))),
  /// n the noise and R the median range the source measures (CloudStatistics): two independent
  /// estimates of the data's scale, the sensor's and the scene's. Either alone varies too much
  /// within one sensor's data: simulated LMS200 scans measure n = 2.0-5.8 mm (5 and 10 mm range
  /// noise, taken normal to the surface) and R = 0.4 m (facing a wall) to 3.8 m (a street), a
  /// smeared scan n = 40 mm; real nodding-SICK scans n = 3.0-3.3 mm, R = 1.45-1.87 m. Their
  /// geometric mean keeps all of these within a factor of 3 of 1, so they resolve to 1, and only
  /// data a decade off change scale (a scene scaled by 0.01 or 10 resolves to exactly 0.01 or 10;
  /// a 0.15 m object scanned to 0.3 mm, to 0.1). A cloud without noise (below 1e-4 of R:
  /// synthetic) is scaled by R / 2 m alone.
  double length_scale = kAuto;

  // Voxel grid (paper: downsampling factor 5-10).
  double icp_voxel_m = 0.1;      ///< voxel edge of the clouds ICP aligns [m]
  double feature_voxel_m = 0.3;  ///< voxel edge of the clouds features are computed on [m]

  // Normals and features.
  double normal_radius_m = 0.75;     ///< neighbourhood of the feature cloud's normals [m]
  double icp_normal_radius_m = 0.3;  ///< neighbourhood of the ICP target's normals [m]
  double feature_radius_m = 1.5;     ///< FPFH / NARF support radius [m]
  int max_neighbors = 40;            ///< neighbours used per feature at most [1]
  int max_feature_points = 2500;     ///< keypoints (evenly sampled) matched per cloud at most [1]

  // NARF (Table 1's alternative): range images of the dense scans, seen from the laser.
  double narf_angular_resolution_deg = 0.5;  ///< range image pixel: the LMS200's step [deg]
  double narf_noise_level_m = 0.02;  ///< z-buffer averages returns within this of the nearest [m]
  /// Keypoint and descriptor support diameter [m]. Small: a wider support takes in what lies
  /// behind a border, which changes with the viewpoint (known-motion test: 0.5 m aligns the
  /// town and the clutter, 1 m neither).
  double narf_support_m = 0.5;

  // Sample-consensus initial alignment.
  int sac_iterations = 20000;        ///< hypotheses drawn at most [1]
  double sac_inlier_m = 0.6;         ///< a correspondence agrees within this distance [m]
  double sac_edge_similarity = 0.9;  ///< prerejection: sampled edge lengths agree to this ratio [1]
  int sac_min_inliers = 10;          ///< fewer agreeing correspondences: alignment failed [1]
  /// Distinct hypotheses of the consensus (best and runners-up) that ICP refines; the one that
  /// fits best (inlier ratio) wins, but of two poses one slide apart whose fits lie within 1.2x,
  /// the one the scene pins more firmly (free_ratio, degeneracy_ratio; mapping/README.md). 1: only
  /// the consensus' best [1].
  int sac_hypotheses = 4;
  /// Weakest / strongest point-to-plane constraint (translation or rotation) below this: the
  /// solution is probed for degeneracy (a corridor, an open plane) by restarting ICP off it [1].
  double degeneracy_ratio = 0.05;
  /// A pose ICP reached from a guess (odometry, constant velocity, a grid of starts around one) is
  /// probed along every translation and rotation axis constrained below this ratio: no feature
  /// consensus backs it, and a few points on the wrong surface can make a free direction look
  /// constrained [1].
  double guess_degeneracy_ratio = 0.2;
  /// A translation constrained below this ratio is free whatever its probe says: a handful of
  /// points decide it, and ICP from either side can end in the same wrong pose (registration_eval,
  /// --targets 25: 5 of the 11 wrong poses reported as successes lay below 0.005, none of the 885
  /// correct ones; facing a wall 0.37 m ahead, 0.0013). Rotations are always probed: their ratio
  /// compares lever arms, the scene's shape (a wall seen 10 m along and 0.5 m up: pitch 0.004 of
  /// yaw, fixed by every wall point to 0.085 deg), not how many points decide them [1].
  double free_ratio = 0.005;
  double degeneracy_probe_m = 1.0;     ///< restart offset of the probe; it must come back [m]
  double degeneracy_probe_deg = 10.0;  ///< restart rotation of the probe about a weak axis [deg]
  /// A weakly constrained feature alignment is also tried this far along its weak direction
  /// (repeated structure along a hall or street; 0 disables) [m].
  double degeneracy_search_m = 2.0;
  /// The prior's guess and the features disagree: ICP from a grid of starts within this of the
  /// guess (0 disables) [m] ...
  double guess_search_m = 0.6;
  double guess_search_deg = 12.0;  ///< ... turned up to this about the vertical [deg]
  /// Degenerate geometry: the directions the scans leave unconstrained are taken from the odometry
  /// guess only when the prior bounds its error (RegistrationPrior::odometry_uncertainty) within
  /// this; otherwise the pose is not determined and the odometry path is a failure. The
  /// constant-velocity fallback (the paper's corridor assumption) may always supply them [m] ...
  double carry_max_m = 0.05;
  /// ... and about an unconstrained rotation axis (a heading off by 0.3 deg carried on open terrain
  /// moved the free translation 5-7 cm) [deg]
  double carry_max_deg = 0.5;

  // Non-linear ICP (Levenberg-Marquardt).
  int icp_max_iterations = 40;       ///< [1]
  double icp_epsilon = 1e-5;         ///< stop when the relative error change is below this [1]
  double icp_max_distance_m = 0.5;   ///< correspondences farther apart are ignored at first [m]
  /// ... the gate shrinks to this as ICP converges [m]. Converged there, ICP goes on at the
  /// inlier band (inlier_distance_m) when that is narrower, so its last iterations fit exactly the
  /// pairs the result is scored and accepted on. Ending at this gate let pairs the acceptance test
  /// calls outliers pull the pose: on the real corridor pair 0.79 deg / 3.3 cm from slam6d's pose,
  /// 69 % of points within 5 cm against the reference's 75 %; ending at the band 0.58 deg / 1.5 cm,
  /// 74 % (mapping/README.md). Going straight to the band instead (no stage here) narrowed the
  /// basin restarts come back from: a room corner's degeneracy probe no longer returned.
  double icp_min_distance_m = 0.15;
  int icp_max_points = 3000;         ///< source points ICP uses at most (evenly sampled) [1]
  /// A pair whose smaller cloud has fewer points than this after the icp_voxel_m grid is a
  /// confined scene (a room corner: the whole scan spans about a metre), where normals in
  /// icp_normal_radius_m straddle its edges and ICP converges off the truth even when started on
  /// it: the final ICP and the acceptance test run again at half the scale (registration_eval
  /// office pair 6: a 216-voxel source, 0.57 deg off at full scale, 0.09 deg at half; with the
  /// same corner as a 733-voxel target, 1.1 deg -> 0.3 deg). Over two registration_eval samples
  /// (--targets 25, 2 x 250 pairs) the smaller cloud lies below 1000 in 10 pairs (216-942:
  /// corners, a wall or a corridor's end ahead), else at 1079 or more (medians of all clouds:
  /// office 6600, urban 16600, terrain 11700). 0 disables [1].
  int confined_scene_voxels = 1000;

  // Priors, constraint and acceptance.
  double constraint_translation_m = 2.5;   ///< result within this of the prior, when given [m]
  double constraint_rotation_deg = 35.0;   ///< ... and within this rotation of it [deg]
  bool constant_velocity_fallback = true;  ///< use the previous motion when alignment fails
  /// A source point is an inlier within this of the target [m]. auto: the larger of icp_voxel_m
  /// (two samplings of one surface, each reduced to a centroid per voxel, lie up to a voxel apart)
  /// and three standard deviations of the pair's measured noise (CloudStatistics::noise_m of
  /// both clouds, in quadrature).
  double inlier_distance_m = kAuto;
  double min_inlier_ratio = 0.3;   ///< fewer inliers: failure (no overlap / misaligned) [1]
  /// Inlier RMS point-to-plane error above this: failure (the scans do not fit together) [m].
  /// auto: inlier_distance_m / sqrt(3), the RMS of residuals spread evenly across the inlier band:
  /// a fit no better than chance. Why not tighter: the residual does not tell a wrong pose from
  /// the truth (registration_eval, 5 and 10 mm noise: correct alignments 7 mm median, 23 mm at
  /// most; wrong poses that passed 8-16 mm), and real scans that fit at the reference pose leave
  /// 24-34 mm where their local noise is 3 mm: a nodding scanner's calibration bends each scan a
  /// little differently, which no noise measured within one scan shows (mapping/README.md).
  double max_rmse_m = kAuto;
  /// A point a pose puts this much nearer a scan's sensor than that scan saw in its direction
  /// (plus 3 % of its range) lies where the scan saw through; each scan judges the other's points
  /// [m]. auto: the larger of 0.1 m (the LMS200's 9 cm mirror offset from the pitch axis moves a
  /// ray's origin by that much) and three standard deviations of the pair's noise.
  double free_space_margin_m = kAuto;

  /// Throws std::invalid_argument naming the field and value (kAuto is valid where allowed).
  void Validate() const;

  /// The settings for one pair: length_scale resolved from `source` (else kept), every length
  /// multiplied by it, and the gates left auto derived from both clouds' noise. Nothing of the
  /// result is kAuto.
  RegistrationConfig Resolve(const CloudStatistics& source, const CloudStatistics& target) const;
};

/// Reads the section `registration` of a YAML document over the defaults (other sections are left
/// alone). An unknown key, a wrong type or an invalid value throws std::invalid_argument naming
/// `source`, `registration.<key>` and the value.
RegistrationConfig ParseRegistrationConfig(const std::string& yaml_text, const std::string& source);

/// Reads a YAML file with ParseRegistrationConfig; throws std::invalid_argument naming the path
/// when it cannot be read.
RegistrationConfig LoadRegistrationConfig(const std::string& path);

/// The config as a `registration:` YAML section, readable back by ParseRegistrationConfig.
std::string RegistrationConfigToYaml(const RegistrationConfig& config);

}  // namespace pitchlab::mapping
