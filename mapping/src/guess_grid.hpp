#pragma once
// The starts a registration searches around a guess: a 3 x 3 x 3 grid of horizontal steps and
// turns about the vertical.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pitchlab::mapping {

/// The 26 poses around `guess` (T_target_source) but the guess itself: steps of `step_m` along two
/// horizontal directions (the source's x and y levelled: perpendicular to `up_target`) and turns
/// of `step_deg` about `up_target` through the guess's position, each -1, 0 or +1 times. Every
/// start keeps the guess's tilt, so an ICP that holds roll and pitch where its start has them
/// holds them where the guess (the measured tilt) has them. With `up_target` the source's own z
/// (guess.linear().col(2)) this is guess * (x, y, yaw) in the source's frame.
std::vector<Eigen::Isometry3d> GuessGridStarts(const Eigen::Isometry3d& guess, double step_m,
                                               double step_deg, const Eigen::Vector3d& up_target);

}  // namespace pitchlab::mapping
