#pragma once
// The simulated IMU's gyro triad: base_link's orientation as its integrated body rates give it,
// with a seeded constant bias and angle random walk per axis. The scan source reads it per line
// to deskew a scan the robot rocked through (sensors::AssembleScan).

#include <cstdint>
#include <random>

#include <Eigen/Geometry>

#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::sim {

/// A MEMS rate gyro triad; the defaults are the datasheet figures of a tactical-grade part
/// (ADIS16470 class: in-run bias stability 8 deg/h, angle random walk 0.34 deg/sqrt(h)). Errors on
/// by default.
struct ImuConfig {
  std::uint64_t seed = 1;
  bool deskew = true;  ///< scans are deskewed by it (SimRig) ...
  /// ... when it senses a rotation of at least this over the scan: below, the correction is
  /// within the gyros' own error over a scan (3 sigma of the defaults' bias and random walk over
  /// the seed's 18 s: 0.19 deg), and on flat floors bent false drops into far, grazing ground [deg]
  double deskew_min_deg = 0.2;
  double gyro_bias_dps = 0.003;  ///< each axis' constant bias ~ N(0, this), drawn once [deg/s]
  double gyro_noise_dps_rthz = 0.008;  ///< white rate noise density [deg/s/sqrt(Hz)]

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// Integrates the body's true rotation between reads, plus the gyro's errors over that time
/// (the bias times the time, a random walk of the white noise). `sim` must outlive it.
class SimImu {
 public:
  SimImu(const Simulation& sim, const ImuConfig& config);  ///< validates; throws
  /// base_link's orientation in the frame the integration started in (the true one at
  /// construction), with the errors accumulated since.
  Eigen::Quaterniond Orientation();

 private:
  const Simulation& sim_;
  ImuConfig config_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Vector3d bias_rps_;
  Eigen::Quaterniond true_last_;  // the body's true orientation at the last read
  Eigen::Quaterniond sensed_;     // what the gyro integrated up to it
  double last_s_ = 0.0;
};

}  // namespace pitchlab::sim
