#pragma once
// Pairwise scan registration, the paper's Algorithm 1: voxel grid, normals, features, sample-
// consensus initial alignment, non-linear ICP (Levenberg-Marquardt); with an odometry prior, a
// geometric constraint around it and a constant-velocity fallback.

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "pitchlab/mapping/cloud_statistics.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration_config.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Where the initial alignment handed to ICP came from.
enum class RegistrationPath {
  kFeatures,  ///< sample consensus on feature correspondences
  kOdometry,  ///< the odometry prior (features off, failed or outside the constraint)
  kFallback,  ///< constant velocity: the previous pair's motion (features failed / ambiguous)
};

/// "features", "odometry", "fallback".
const char* ToString(RegistrationPath path);

/// What a registration concluded.
enum class RegistrationOutcome {
  kSuccess,    ///< one pose, determined by the scans (or a trusted guess along what they leave free)
  kAmbiguous,  ///< the scans fit distinct poses comparably (a corridor's axis) and nothing decides
  kFailure,    ///< no acceptable fit (no overlap, constraint or tilt violated, bad fit)
};

/// "success", "ambiguous", "failure".
const char* ToString(RegistrationOutcome outcome);

/// How far a guess may be off the true motion at most (e.g. odometry's drift over the step).
struct GuessUncertainty {
  double translation_m = 0;  ///< [m]
  double rotation_deg = 0;   ///< [deg]
};

/// The odometry guess's roll and pitch were measured against gravity (an inclinometer read at
/// standstill): a result that tilts the source farther from them is wrong however well it fits.
struct MeasuredTilt {
  Eigen::Vector3d up_target = Eigen::Vector3d::UnitZ();  ///< gravity's up in the target frame
  double tolerance_deg = 1.0;  ///< the guess's tilt is right within this [deg]; finite, > 0
};

/// What the caller knows before aligning. Both transforms are T_target_source.
struct RegistrationPrior {
  std::optional<Eigen::Isometry3d> odometry;         ///< odometry's guess; enables the constraint
  std::optional<Eigen::Isometry3d> previous_motion;  ///< last pair's estimate (constant velocity)
  /// How far `odometry` may be off; unset: unknown. Where the scans leave a direction unconstrained
  /// (a corridor's axis, yaw on an open plane) only an odometry guess bounded within the config's
  /// carry_max_m / carry_max_deg may supply it; else the odometry path reports a failure. The
  /// bound also narrows the geometric constraint (constraint_translation_m / _rotation_deg) and
  /// the grid searched around the guess (guess_search_m / _deg) to itself. Finite, >= 0.
  std::optional<GuessUncertainty> odometry_uncertainty;
  /// With an odometry guess: its measured tilt. ICP from the guess whose result tilts the source
  /// more than tolerance_deg from it is re-run with roll and pitch held at the guess's (x, y, z
  /// and the turn about up stay free), and the result says so; any result beyond it is rejected.
  std::optional<MeasuredTilt> tilt;
  /// Where each cloud's sensor (the laser's mirror) stood, in that cloud's frame [m]: normals face
  /// it, and free space is what lies between it and a return. Unset: at the frame's origin.
  std::optional<Eigen::Vector3f> source_sensor, target_sensor;
  /// The one scan the target's sensor took at the target frame's origin, in that frame, when the
  /// target is not that scan itself (a map built from many, whose points were seen from elsewhere).
  /// Where fits cannot decide along a weakly constrained direction (a street, the heading on a
  /// slope), a pose that puts source points in space this scan saw through is refuted. Null: the
  /// target is one scan. Not owned; must outlive the call.
  const PointCloud* target_scan = nullptr;
};

/// Wall time per stage [s] (for both clouds together).
struct StageTimings {
  double voxel_s = 0, normals_s = 0, features_s = 0, initial_alignment_s = 0, icp_s = 0,
         total_s = 0;
};

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// A pose is refuted outright when more than kChangedViewShare of the points one scan's view can
/// judge lie where that scan's beams passed (and at least 0.5 % of all its points: a few points
/// of a thin pole never decide). At the right pose only what changed between the two
/// scans lies there. Measured (RegistrationResult::free_space, register --json):
/// - simulated pairs at their right pose: at most 0.26 % (registration_eval seeds 20120917, 4
///   and 5: 2642 correct successes; thin poles and chair legs one scan's beams hit and the
///   other's pass); scan-to-map in missions (office, urban, terrain seeds 1..20: 765 stops) at
///   most 1.1 %;
/// - the real 3DTK corridor pair at its right pose: 3.1 % and 3.2 % (both ways round; mostly a
///   patch in the room behind a doorway that one scan's beams passed and the other's hit: a door
///   leaf moved, or the doorway's edges seen at two angles);
/// - wrong poses: simulated office aliases 2 m along a desk row, 8.0-11 %; the real pair from
///   priors 2-4 m along the corridor or 20 deg off, 17-20 %.
/// 5 % lies between a real scene's change and an alias, about the geometric mean of 3.2 and 8.0. A
/// scene where more changed between two scans (a crowd passing) is refused with its reason.
inline constexpr double kChangedViewShare = 0.05;

/// Outcome of one registration. `success` false means: do not merge; `reason` says why.
struct RegistrationResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();  ///< maps source into target
  bool success = false;  ///< outcome == kSuccess
  RegistrationOutcome outcome = RegistrationOutcome::kFailure;
  std::string reason;  ///< why it failed, or how it succeeded ("features", notes)
  RegistrationPath path = RegistrationPath::kFeatures;
  double fitness_m2 = 0;    ///< mean squared distance of inlier pairs (PCL's fitness) [m^2]
  double rmse_m = 0;        ///< RMS point-to-plane error of the inlier pairs [m]
  double inlier_ratio = 0;  ///< source points within inlier_distance_m of the target [1]
  double degeneracy = 0;    ///< weakest / strongest constraint direction (1 = isotropic) [1]
  int sac_inliers = 0;      ///< correspondences agreeing with the initial alignment [1]
  int iterations = 0;       ///< ICP iterations run [1]
  StageTimings timings;

  /// Observability of T_target_source, for a perturbation T <- Exp(omega, v) T applied in the
  /// target frame, ordered (omega_x, omega_y, omega_z [rad], v_x, v_y, v_z [m]). `information`:
  /// the final ICP's point-to-plane Gauss-Newton Hessian over its inlier pairs divided by the
  /// residual's variance (rmse_m^2). `covariance`: its inverse, where a direction the scans leave
  /// (nearly) free, or that was kept at a guess, takes the guess's bound instead (the prior's error
  /// bound, else the geometric constraint's limit): a pose taken from a guess is only as good as
  /// the guess. Both are zero when no ICP result was scored.
  Matrix6d information = Matrix6d::Zero();
  Matrix6d covariance = Matrix6d::Zero();
  /// Free-space evidence at T_target_source (Huber and Hebert 2003): of the points a scan's view
  /// can judge (in its field of view, beyond the mirror's offset), the share the pose puts where
  /// that scan's beams passed through. A static scene at the right pose leaves next to none
  /// there; a scene that changed between the scans (a door, a person) or a wrong pose does.
  struct FreeSpace {
    int source_judged = 0;        ///< the source's ICP points the target's view judges [1]
    double source_violating = 0;  ///< share of those where the target saw through [1]
    int target_judged = 0;        ///< the target's ICP points the source's view judges [1]
    double target_violating = 0;  ///< share of those where the source saw through [1]
  };
  FreeSpace free_space;  ///< all zero when no pose was scored
  /// What the clouds measured (scale, spacing, noise) and the settings they resolved to: every
  /// `auto` of the config replaced by its value (RegistrationConfig::Resolve).
  CloudStatistics source_statistics, target_statistics;
  RegistrationConfig settings;
};

/// Aligns `source` to `target` (both [m], each in its own base_link). Bad input (empty, non-finite
/// points, too few points after the voxel grid) is an Error (kInvalidArgument); an alignment that
/// fails (no overlap, features ambiguous without a fallback, constraint violated) is a result
/// with success == false and the reason. Deterministic: the same input gives the same output.
[[nodiscard]] Result<RegistrationResult> Register(const PointCloud& target,
                                                  const PointCloud& source,
                                                  const RegistrationPrior& prior,
                                                  const RegistrationConfig& config);

/// A target cloud and what registration derives from it alone (its statistics, voxel grids, the
/// ICP target's search structures and normals, the feature cloud's FPFH), each made once and kept.
/// A mission knows its next target, the local map around its last pose, before the robot has
/// driven to the next stop: Prepare makes these parts then (on a core the drive leaves idle), and
/// Register uses them. Register with it gives what Register with the cloud gives, to the bit: a
/// part the call needs with other settings than it was prepared with is made afresh. Not for two
/// calls at once (Register may add parts).
class RegistrationTarget {
 public:
  /// `sensor`: where the target's sensor stood, in its frame (RegistrationPrior::target_sensor).
  RegistrationTarget(PointCloud cloud, std::optional<Eigen::Vector3f> sensor);
  ~RegistrationTarget();
  RegistrationTarget(RegistrationTarget&&) noexcept;
  RegistrationTarget& operator=(RegistrationTarget&&) noexcept;

  const PointCloud& cloud() const;
  /// Makes the parts a registration with `config` needs, its `auto` settings resolved as if the
  /// source measured like this target. Bad input is left for Register to name.
  void Prepare(const RegistrationConfig& config);

 private:
  friend Result<RegistrationResult> Register(RegistrationTarget&, const PointCloud&,
                                             const RegistrationPrior&, const RegistrationConfig&);
  struct Parts;
  std::unique_ptr<Parts> parts_;
  std::optional<Eigen::Vector3f> sensor_;
};

/// Register against a prepared target (`prior.target_sensor` should be the target's sensor: parts
/// made for another are made again).
[[nodiscard]] Result<RegistrationResult> Register(RegistrationTarget& target,
                                                  const PointCloud& source,
                                                  const RegistrationPrior& prior,
                                                  const RegistrationConfig& config);

/// Rotation angle of `T` [deg] and translation norm [m]: the error measure against ground truth.
struct PoseError {
  double rotation_deg = 0;
  double translation_m = 0;
};
/// Error of `estimate` against `truth` (both T_target_source): angle and norm of truth^-1 estimate.
PoseError ComparePoses(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);

/// Angle between the up directions `a` and `b` (both T_target_source) give the source, `up_target`
/// being up in the target frame [deg]: their difference in roll and pitch, blind to a turn about
/// up.
double TiltBetween(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                   const Eigen::Vector3d& up_target);

/// x, y, z [m], roll, pitch, yaw [deg] (fixed-axis XYZ, as ROS) -> transform.
Eigen::Isometry3d PoseFromXyzRpyDeg(double x, double y, double z, double roll_deg, double pitch_deg,
                                    double yaw_deg);

}  // namespace pitchlab::mapping
