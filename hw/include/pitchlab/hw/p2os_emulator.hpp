#pragma once
// An emulated Pioneer P3 microcontroller (P2OS/ARCOS) on a pseudo-terminal: SYNC0/1/2 handshake,
// OPEN, ENABLE, VEL/RVEL, SETO, CLOSE, E_STOP, a 2 s watchdog, standard SIPs every 100 ms.
// STOP, VEL2, SONAR and CONFIG are accepted (CONFIG is not answered). Motion comes from callbacks
// (the simulated base) or a built-in unicycle.

#include <functional>
#include <mutex>
#include <string>

#include "pitchlab/hw/emulated_device.hpp"
#include "pitchlab/hw/p2os_protocol.hpp"

namespace pitchlab::hw {

/// What the robot's wheel encoders report, integrated since power-on.
struct BaseState {
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;  ///< odometry pose [m, m, rad]
  double left_mps = 0.0, right_mps = 0.0;      ///< wheel speeds [m/s]
  double omega_rps = 0.0;                      ///< yaw rate [rad/s]
  bool stall_left = false, stall_right = false;
  double battery_v = 12.8;  ///< [V]
};

/// The base's physics as the microcontroller sees it.
struct BasePhysics {
  std::function<void(double v_mps, double omega_rps)> command;  ///< new wheel setpoint
  std::function<BaseState()> state;                             ///< current odometry
};

struct P2osEmulatorConfig {
  int baud = 9600;            ///< [bit/s]
  double sip_period_s = 0.1;  ///< standard SIP rate [s]
  double watchdog_s = 2.0;    ///< motors stop after this long without a packet [s]
  double track_m = 0.33;      ///< built-in model's wheel track [m]
  /// SYNC2 strings. "p3at-sh" (an ARCOS P3-AT) is the subclass whose client tables take the
  /// SIP's positions and speeds as mm and mm/s, as sent here (docs/hardware_interop.md).
  std::string name = "pitchlab", type = "Pioneer", subtype = "p3at-sh";
};

class P2osEmulator final : public EmulatedDevice {
 public:
  /// `physics` empty: a unicycle integrating the command. Throws like EmulatedDevice.
  explicit P2osEmulator(const P2osEmulatorConfig& config, BasePhysics physics = {},
                        std::string link_path = "");
  ~P2osEmulator() override;
  /// True after OPEN until CLOSE.
  bool connected() const { return connected_; }
  /// True while motors are enabled.
  bool motors_enabled() const { return enabled_; }
  /// The wheel setpoint in force: forward [m/s], yaw rate [rad/s].
  std::pair<double, double> command() const { return {v_mps_, omega_rps_}; }

 private:
  void OnBytes(const std::uint8_t* bytes, std::size_t size) override;
  void OnIdle() override;
  void OnPowerOn() override;
  void Handle(const std::vector<std::uint8_t>& payload);
  void Command(double v_mps, double omega_rps);
  BaseState State();

  P2osEmulatorConfig config_;
  BasePhysics physics_;
  p2os::PacketReader reader_;
  int sync_stage_ = 0;  // next SYNC expected; 3 = synced
  std::atomic<bool> connected_{false}, enabled_{false};
  std::atomic<double> v_mps_{0.0}, omega_rps_{0.0};
  double last_packet_s_ = 0.0, next_sip_s_ = 0.0, last_step_s_ = 0.0;
  BaseState own_;     // built-in model state
  BaseState origin_;  // SETO: odometry reported relative to this
};

}  // namespace pitchlab::hw
