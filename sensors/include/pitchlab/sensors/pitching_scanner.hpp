#pragma once
// Stop-and-scan 3D acquisition: step the pitch axis, take a line at each step, assemble by Eq. 1.
// Written once against the seam interfaces, so simulation and hardware share it.

#include <functional>
#include <optional>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"
#include "pitchlab/sensors/scan3d.hpp"
#include "pitchlab/sensors/scan_source.hpp"

namespace pitchlab::sensors {

/// The pitch sweep of one 3D scan. The seed: 200 lines over 100 deg.
struct ScanPatternConfig {
  double pitch_start_deg = -40.0;  ///< first line, negative = nose up [deg]
  double pitch_end_deg = 60.0;     ///< last line [deg]
  int lines = 200;                 ///< lines per scan
  int line_timeout_ms = 2000;      ///< a line or a move that takes longer is a device fault [ms]

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// Any source of full 3D scans: what the mapping pipeline consumes.
class ScanSource {
 public:
  virtual ~ScanSource() = default;
  /// One full 3D scan in base_link, or the first device error met.
  [[nodiscard]] virtual Result<Scan3D> Acquire() = 0;
};

/// Drives a PitchAxis and a LineScanner through a ScanPatternConfig. Both must outlive it.
class PitchingScanSource final : public ScanSource {
 public:
  /// Called after each line with (lines done, lines total).
  using Progress = std::function<void(int, int)>;

  /// base_link's orientation in a frame fixed to the ground (an IMU's integrated rates; only its
  /// changes during a scan matter), or nullopt where the sensor has none to give.
  using AttitudeProbe = std::function<std::optional<Eigen::Quaterniond>()>;

  PitchingScanSource(LineScanner& scanner, PitchAxis& axis, ScanPatternConfig pattern,
                     MountConfig mount);
  void set_progress(Progress progress) { progress_ = std::move(progress); }
  /// Read after every line; when it answered for every line and sensed a rotation of at least
  /// `min_rotation_rad` between a line and the last, the scan is deskewed (AssembleScan). Below
  /// that (the sensor's own error over a scan) the correction would only add the sensor's error.
  void set_attitude_probe(AttitudeProbe probe, double min_rotation_rad = 0.0) {
    attitude_ = std::move(probe);
    min_rotation_rad_ = min_rotation_rad;
  }
  [[nodiscard]] Result<Scan3D> Acquire() override;

 private:
  LineScanner& scanner_;
  PitchAxis& axis_;
  ScanPatternConfig pattern_;
  MountConfig mount_;
  Progress progress_;
  AttitudeProbe attitude_;
  double min_rotation_rad_ = 0.0;
};

}  // namespace pitchlab::sensors
