#pragma once
// real_eval's false-success check (issue 16): one real pair registered from priors that are
// wrong, with a stated error bound that excludes the truth and with none, and the pair the wrong
// way round. Each result must be near the true pose or reported as failed / ambiguous.

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration_config.hpp"

namespace pitchlab::benchmarks {

/// The pair: the target and source points in their own frames, where each sensor stood there,
/// and two poses of the source in the target's frame to hold results to: the reference's and our
/// own (with the odometry prior). The reference is good to 0.5-1 deg only (3DTK: two slam6d runs
/// of the same scans lie 7.9 cm apart), so each result is compared with both.
struct WrongPriorPair {
  const mapping::PointCloud* target = nullptr;
  const mapping::PointCloud* source = nullptr;
  Eigen::Vector3f target_sensor = Eigen::Vector3f::Zero();
  Eigen::Vector3f source_sensor = Eigen::Vector3f::Zero();
  Eigen::Isometry3d reference = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d ours = Eigen::Isometry3d::Identity();
};

/// Registers the pair from priors our pose moved 1, 2 and 3 m along the source's x (a corridor's
/// axis, both ways), turned 10, -20 and 30 deg about its z, and 2 m with 20 deg; each bounded by
/// half its offset (so the bound excludes the truth) and unbounded. Then the source and target
/// swapped with our pose as the prior: the wrong way round. Reports each case (outcome, errors
/// against the reference and against ours) and counts the successes more than 1 deg / 5 cm from
/// the reference and from ours.
nlohmann::json CheckWrongPriors(const WrongPriorPair& pair,
                                const mapping::RegistrationConfig& config);

}  // namespace pitchlab::benchmarks
