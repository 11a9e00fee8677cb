#include "pitchlab/hw/hw_rig.hpp"

namespace pitchlab::hw {

HwRig::HwRig(const HwRigConfig& config, ClockFn clock)
    : scanner_(std::make_unique<Lms200Driver>(config.lms200, clock)),
      axis_(std::make_unique<PitchUnitDriver>(config.pitch_unit)),
      base_(config.base ? std::make_unique<P2osDriver>(*config.base, clock) : nullptr),
      source_(std::make_unique<sensors::PitchingScanSource>(*scanner_, *axis_, config.pattern,
                                                            config.mount)) {}

Result<sensors::Scan3D> HwRig::Acquire() {
  // Stop-scan-go: the base stands still during the sweep.
  if (base_) {
    Result<sensors::Odometry> stopped = base_->Drive(0.0, 0.0, 0.2);
    if (!stopped)
      return Fail(stopped.error().code, "stopping the base: " + stopped.error().message);
  }
  return source_->Acquire();
}

}  // namespace pitchlab::hw
