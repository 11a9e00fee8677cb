#pragma once
// The total least squares plane through a set of points, its normal turned up: what the floor
// fits (ground_level.cpp, line_pitch.cpp) have in common.

#include <utility>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace pitchlab::mapping {

/// The plane n . p = d through `points` (a container of Eigen 3-vectors, float or double) with n
/// the smallest eigenvector of their covariance, n.z() >= 0. Needs at least one point.
template <typename Points>
std::pair<Eigen::Vector3d, double> UpPlaneThrough(const Points& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p.template cast<double>();
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    const Eigen::Vector3d e = p.template cast<double>() - mean;
    cov += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  if (n.z() < 0) n = -n;
  return {n, n.dot(mean)};
}

}  // namespace pitchlab::mapping
