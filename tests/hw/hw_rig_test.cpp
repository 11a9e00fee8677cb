// The hardware scan source against all three emulators: the same Scan3D the simulator builds.

#include <gtest/gtest.h>

#include <cmath>

#include "pitchlab/hw/hw_rig.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"
#include "pitchlab/hw/pitch_unit_emulator.hpp"

namespace pitchlab::hw {
namespace {

TEST(HwRig, ScansAFlatWallThroughTheEmulatedDevices) {
  Lms200Emulator lms(Lms200EmulatorConfig{});
  PitchUnitEmulator pitch_unit(sensors::PitchUnitConfig{});
  P2osEmulator base(P2osEmulatorConfig{38400});
  HwRigConfig config;
  config.lms200.device = lms.path();
  config.lms200.lms.baud = 38400;
  config.pitch_unit.device = pitch_unit.path();
  config.base = P2osDriverConfig{};
  config.base->device = base.path();
  config.base->baud = 38400;
  config.pattern.lines = 4;
  config.pattern.pitch_start_deg = -9.0;
  config.pattern.pitch_end_deg = 9.0;
  HwRig rig(config);
  Result<sensors::Scan3D> scan = rig.Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->lines.size(), 4u);
  EXPECT_FALSE(scan->has_truth);
  EXPECT_NEAR(scan->lines.front().pitch_rad, -9.0 * M_PI / 180, 0.01);
  EXPECT_NEAR(scan->lines.back().pitch_rad, 9.0 * M_PI / 180, 0.01);
  EXPECT_GT(scan->points.size(), 4u * 300u);
  // The wall 3 m ahead of the mirror, seen at the level line: x near 3 m + mount offset.
  for (const auto& p : scan->points) {
    if (p.line == 1 || p.line == 2) ASSERT_GT(p.x, 2.5f);
  }
}

}  // namespace
}  // namespace pitchlab::hw
