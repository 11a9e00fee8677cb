#pragma once
// Tiny inline worlds for the sim tests (STYLE.md: raw-string MJCF in the test).

namespace pitchlab::sim::testing {

/// 20 x 20 m floor, a 1 m box obstacle at (5, 0), pitchlab custom fields.
inline constexpr char kFlatWorld[] = R"(
<mujoco model="flat">
  <option timestep="0.002"/>
  <custom>
    <text name="pitchlab:description" data="flat test floor"/>
    <numeric name="pitchlab:bounds" data="-9 -9 9 9"/>
    <numeric name="pitchlab:default_start" data="1 2 90"/>
    <numeric name="pitchlab:geodetic_origin" data="47.5 19.0 100"/>
  </custom>
  <worldbody>
    <light pos="0 0 5" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="obstacle" type="box" pos="5 0 0.5" size="0.5 0.5 0.5"/>
  </worldbody>
</mujoco>)";

/// Floor without pitchlab:bounds (the floor's edge is the world's edge), a wall whose face is at
/// x = 3 m spanning y = -5 .. 5 m and z = 0 .. 2 m.
inline constexpr char kWallWorld[] = R"(
<mujoco model="wall">
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="wall" type="box" pos="3.05 0 1" size="0.05 5 1"/>
  </worldbody>
</mujoco>)";

/// Box floors only (as in the office world), a thin 2.5 m wall along y = 1 and a ramp tilted
/// 10 deg about y centred at (-5, 0).
inline constexpr char kBoxFloorWorld[] = R"(
<mujoco model="box_floor">
  <worldbody>
    <geom name="floor" type="box" pos="0 0 -0.05" size="10 10 0.05"/>
    <geom name="thin_wall" type="box" pos="3 1 1.25" size="2 0.05 1.25"/>
    <geom name="ramp" type="box" pos="-5 0 0.3" size="1.5 1.5 0.05" euler="0 10 0"/>
  </worldbody>
</mujoco>)";

}  // namespace pitchlab::sim::testing
