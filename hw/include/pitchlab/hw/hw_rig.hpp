#pragma once
// The real robot wired up behind the same seams as sim::SimRig: LMS200 + pitch unit through
// sensors::PitchingScanSource (the same Eq. 1 assembly as in simulation), and the P3 base.

#include <memory>
#include <optional>

#include "pitchlab/hw/lms200_driver.hpp"
#include "pitchlab/hw/p2os_driver.hpp"
#include "pitchlab/hw/pitch_unit_driver.hpp"
#include "pitchlab/sensors/pitching_scanner.hpp"

namespace pitchlab::hw {

/// Device paths and settings of a hardware run (`backend: hw`).
struct HwRigConfig {
  Lms200DriverConfig lms200;
  PitchUnitDriverConfig pitch_unit;
  std::optional<P2osDriverConfig> base;  ///< none: a scanner on a tripod
  sensors::ScanPatternConfig pattern;
  sensors::MountConfig mount;
};

/// Drivers + PitchingScanSource. Scans carry no ground truth (has_truth false).
class HwRig final : public sensors::ScanSource {
 public:
  /// Opens and initialises every device; throws std::runtime_error naming the device that failed.
  explicit HwRig(const HwRigConfig& config, ClockFn clock = {});
  /// Stops the base (if any), then one pitch sweep; the first device error ends it.
  [[nodiscard]] Result<sensors::Scan3D> Acquire() override;

  Lms200Driver& scanner() { return *scanner_; }
  PitchUnitDriver& pitch_axis() { return *axis_; }
  P2osDriver* base() { return base_.get(); }  ///< null without a base
  sensors::PitchingScanSource& scan_source() { return *source_; }

 private:
  std::unique_ptr<Lms200Driver> scanner_;
  std::unique_ptr<PitchUnitDriver> axis_;
  std::unique_ptr<P2osDriver> base_;
  std::unique_ptr<sensors::PitchingScanSource> source_;
};

}  // namespace pitchlab::hw
