#include "pitchlab/mapping/trajectory_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {

namespace {

using Poses = std::vector<Eigen::Isometry3d>;

Result<void> CheckPair(const Poses& estimate, const Poses& truth, std::size_t min_poses,
                       const char* metric) {
  if (estimate.size() != truth.size()) {
    return Fail(Error::Code::kInvalidArgument,
                std::string(metric) + ": " + std::to_string(estimate.size()) +
                    " estimated poses but " + std::to_string(truth.size()) + " true ones");
  }
  if (estimate.size() < min_poses) {
    return Fail(Error::Code::kInvalidArgument, std::string(metric) + ": needs at least " +
                                                   std::to_string(min_poses) + " poses, got " +
                                                   std::to_string(estimate.size()));
  }
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    if (!estimate[i].matrix().allFinite() || !truth[i].matrix().allFinite()) {
      return Fail(Error::Code::kInvalidArgument,
                  std::string(metric) + ": pose " + std::to_string(i) + " is not finite");
    }
  }
  return {};
}

// Running RMS and maximum of the translation and rotation parts of error transforms.
struct ErrorAccumulator {
  void Add(double translation, double rotation) {
    ++count;
    translation_sq += translation * translation;
    rotation_sq += rotation * rotation;
    translation_max = std::max(translation_max, translation);
    rotation_max = std::max(rotation_max, rotation);
  }
  RelativePoseError Relative() const {
    return {count, std::sqrt(translation_sq / count), translation_max,
            std::sqrt(rotation_sq / count), rotation_max};
  }
  int count = 0;
  double translation_sq = 0, rotation_sq = 0, translation_max = 0, rotation_max = 0;
};

AbsoluteTrajectoryError Ate(const Poses& estimate, const Poses& truth,
                            const Eigen::Isometry3d& T_truth_estimate) {
  ErrorAccumulator acc;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const PoseError e = ComparePoses(T_truth_estimate * estimate[i], truth[i]);
    acc.Add(e.translation_m, e.rotation_deg);
  }
  // ComparePoses' translation is |R_true^T (t_est - t_true)|: the position error's length.
  AbsoluteTrajectoryError out;
  out.poses = acc.count;
  out.rmse_m = std::sqrt(acc.translation_sq / acc.count);
  out.max_m = acc.translation_max;
  out.rotation_rmse_deg = std::sqrt(acc.rotation_sq / acc.count);
  out.T_truth_estimate = T_truth_estimate;
  return out;
}

// E = (T_true_i^-1 T_true_j)^-1 (T_est_i^-1 T_est_j).
PoseError RelativeError(const Poses& estimate, const Poses& truth, std::size_t i, std::size_t j) {
  return ComparePoses(estimate[i].inverse() * estimate[j], truth[i].inverse() * truth[j]);
}

}  // namespace

Result<AbsoluteTrajectoryError> AbsoluteTrajectoryErrorUnaligned(const Poses& estimate,
                                                                 const Poses& truth) {
  if (auto ok = CheckPair(estimate, truth, 1, "ATE"); !ok) return tl::make_unexpected(ok.error());
  return Ate(estimate, truth, Eigen::Isometry3d::Identity());
}

Result<AbsoluteTrajectoryError> AbsoluteTrajectoryErrorAligned(const Poses& estimate,
                                                               const Poses& truth) {
  if (auto ok = CheckPair(estimate, truth, 1, "ATE"); !ok) return tl::make_unexpected(ok.error());
  Eigen::Matrix3Xd from(3, estimate.size()), to(3, truth.size());
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    from.col(i) = estimate[i].translation();
    to.col(i) = truth[i].translation();
  }
  const Eigen::Isometry3d T_truth_estimate(Eigen::umeyama(from, to, /*with_scaling=*/false));
  return Ate(estimate, truth, T_truth_estimate);
}

Result<RelativePoseError> RelativePoseErrorPerStop(const Poses& estimate, const Poses& truth) {
  if (auto ok = CheckPair(estimate, truth, 2, "RPE"); !ok) return tl::make_unexpected(ok.error());
  ErrorAccumulator acc;
  for (std::size_t i = 0; i + 1 < estimate.size(); ++i) {
    const PoseError e = RelativeError(estimate, truth, i, i + 1);
    acc.Add(e.translation_m, e.rotation_deg);
  }
  return acc.Relative();
}

Result<RelativePoseError> RelativePoseErrorPerMetre(const Poses& estimate, const Poses& truth,
                                                    double segment_m) {
  if (auto ok = CheckPair(estimate, truth, 2, "RPE"); !ok) return tl::make_unexpected(ok.error());
  if (!(std::isfinite(segment_m) && segment_m > 0)) {
    return Fail(Error::Code::kInvalidArgument,
                "RPE per metre: segment_m = " + NumberText(segment_m) + ": must be > 0");
  }
  std::vector<double> path_m(truth.size(), 0.0);  // true path length from stop 0
  for (std::size_t i = 1; i < truth.size(); ++i) {
    path_m[i] = path_m[i - 1] + (truth[i].translation() - truth[i - 1].translation()).norm();
  }
  ErrorAccumulator acc;
  std::size_t j = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    j = std::max(j, i + 1);  // the segment's end only moves forward as its start does
    while (j < truth.size() && path_m[j] - path_m[i] < segment_m) ++j;
    if (j == truth.size()) break;
    const double length_m = path_m[j] - path_m[i];
    const PoseError e = RelativeError(estimate, truth, i, j);
    acc.Add(e.translation_m / length_m, e.rotation_deg / length_m);
  }
  if (acc.count == 0) {
    return Fail(Error::Code::kInvalidArgument,
                "RPE per metre: the true path (" + NumberText(path_m.back()) +
                    " m) is shorter than one segment (" + NumberText(segment_m) + " m)");
  }
  return acc.Relative();
}

bool IsWrongLoopClosure(const Eigen::Isometry3d& T_a_b_estimated,
                        const Eigen::Isometry3d& T_a_b_true) {
  const PoseError e = ComparePoses(T_a_b_estimated, T_a_b_true);
  return e.translation_m > kWrongLoopTranslationM || e.rotation_deg > kWrongLoopRotationDeg;
}

}  // namespace pitchlab::mapping
