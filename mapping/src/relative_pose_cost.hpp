#pragma once
// The pose graph's edge residual as a Ceres auto-diff functor (private: Ceres stays out of the
// public headers). Convention: pose_graph.hpp.

#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pitchlab::mapping {

/// Residual S * e of one edge a -> b, S the upper Cholesky factor of its information (S^T S = I):
/// e = Log(Z * (T_map_a^-1 T_map_b)^-1) with Log(R, t) = (angle-axis of R, t), the inverse of the
/// registration's Exp(omega, v) = [R(omega), v]. Parameter blocks: a's quaternion (Eigen order
/// x, y, z, w) and translation, then b's.
class RelativePoseCost {
 public:
  RelativePoseCost(const Eigen::Isometry3d& T_a_b_measured,
                   const Eigen::Matrix<double, 6, 6>& sqrt_information)
      : q_measured_(T_a_b_measured.rotation()),
        t_measured_(T_a_b_measured.translation()),
        sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* q_a_ptr, const T* t_a_ptr, const T* q_b_ptr, const T* t_b_ptr,
                  T* residual_ptr) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(q_a_ptr), q_b(q_b_ptr);
    const Eigen::Map<const Vector3> t_a(t_a_ptr), t_b(t_b_ptr);
    // The graph's estimate of T_a_b = T_map_a^-1 * T_map_b.
    const Eigen::Quaternion<T> q_ab = q_a.conjugate() * q_b;
    const Vector3 t_ab = q_a.conjugate() * (t_b - t_a);
    // E = Z * estimate^-1 = [R_Z R_ab^T, t_Z - R_Z R_ab^T t_ab]: the target-frame perturbation.
    const Eigen::Quaternion<T> q_e = q_measured_.cast<T>() * q_ab.conjugate();
    const Vector3 t_e = t_measured_.cast<T>() - q_e * t_ab;
    const T q_e_wxyz[4] = {q_e.w(), q_e.x(), q_e.y(), q_e.z()};
    Eigen::Matrix<T, 6, 1> e;
    ceres::QuaternionToAngleAxis(q_e_wxyz, e.data());  // takes the shorter way round (w < 0)
    e.template tail<3>() = t_e;
    Eigen::Map<Eigen::Matrix<T, 6, 1>> residual(residual_ptr);
    residual = sqrt_information_.cast<T>() * e;
    return true;
  }

 private:
  Eigen::Quaterniond q_measured_;
  Eigen::Vector3d t_measured_;
  Eigen::Matrix<double, 6, 6> sqrt_information_;
};

}  // namespace pitchlab::mapping
