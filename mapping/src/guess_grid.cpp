#include "guess_grid.hpp"

namespace pitchlab::mapping {

std::vector<Eigen::Isometry3d> GuessGridStarts(const Eigen::Isometry3d& guess, double step_m,
                                               double step_deg, const Eigen::Vector3d& up_target) {
  const Eigen::Vector3d up = up_target.normalized();
  const Eigen::Vector3d forward = guess.linear().col(0);
  Eigen::Vector3d ex = forward - up * up.dot(forward);  // the source's x, levelled
  ex = ex.norm() > 1e-6 ? ex.normalized() : up.unitOrthogonal();
  const Eigen::Vector3d ey = up.cross(ex);
  const Eigen::Vector3d at = guess.translation();
  const double step_rad = step_deg * 3.14159265358979323846 / 180.0;
  std::vector<Eigen::Isometry3d> out;
  for (int ix = -1; ix <= 1; ++ix) {
    for (int iy = -1; iy <= 1; ++iy) {
      for (int iyaw = -1; iyaw <= 1; ++iyaw) {
        if (ix == 0 && iy == 0 && iyaw == 0) continue;  // the guess itself
        const Eigen::Vector3d step = ix * step_m * ex + iy * step_m * ey;
        out.push_back(Eigen::Translation3d(at + step) * Eigen::AngleAxisd(iyaw * step_rad, up) *
                      Eigen::Translation3d(-at) * guess);
      }
    }
  }
  return out;
}

}  // namespace pitchlab::mapping
