#pragma once
// An emulated Pioneer P3 microcontroller (P2OS/ARCOS) on a pseudo-terminal: SYNC0/1/2 handshake,
// OPEN, ENABLE, VEL/RVEL/VEL2, STOP, SETO, CLOSE, E_STOP, auxiliary power, a 2 s watchdog,
// standard SIPs every 100 ms in the robot units of its subclass. SONAR and CONFIG are accepted
// and not answered (docs/hardware_interop.md). Motion comes from callbacks (the simulated base)
// or a built-in unicycle.

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

#include "pitchlab/hw/emulated_device.hpp"
#include "pitchlab/hw/p2os_protocol.hpp"
#include "pitchlab/hw/pioneer_params.hpp"

namespace pitchlab::hw {

/// What the robot's wheel encoders report, integrated since power-on.
struct BaseState {
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;  ///< odometry pose [m, m, rad]
  double left_mps = 0.0, right_mps = 0.0;      ///< wheel speeds [m/s]
  double omega_rps = 0.0;                      ///< yaw rate [rad/s]
  bool stall_left = false, stall_right = false;
  double battery_v = 12.8;                           ///< [V]
  double left_travel_m = 0.0, right_travel_m = 0.0;  ///< wheel travel the encoders count [m]
};

/// The base's physics as the microcontroller sees it.
struct BasePhysics {
  std::function<void(double v_mps, double omega_rps)> command;  ///< new wheel setpoint
  std::function<BaseState()> state;                             ///< current odometry
  /// The track the physics converts (v, omega) to wheel speeds with [m]: VEL2's wheel speeds
  /// become (v, omega) through it. 0: P2osEmulatorConfig::track_m.
  double track_m = 0.0;
  /// One encoder tick of wheel travel [m]: parked, wheel travel below it is not motion. 0: one
  /// SIP position unit (DistConvFactor mm).
  double encoder_tick_m = 0.0;
  /// E_STOP (55): stop at once, without the deceleration ramp; empty: a command of zero.
  std::function<void()> emergency_stop;
  /// Auxiliary power output `output` switched on / off (command 31); empty: ignored.
  std::function<void(int output, bool on)> aux_power;
};

struct P2osEmulatorConfig {
  /// [bit/s]; 9600, the rate a P3 opens its host port at (ARIA and ROS p2os connect there and
  /// change it only after reading the robot's CONFIG packet).
  int baud = 9600;
  double sip_period_s = 0.1;  ///< standard SIP rate [s]
  double watchdog_s = 2.0;    ///< motors stop after this long without a packet [s]
  double track_m = 0.33;      ///< built-in model's wheel track [m]
  /// SYNC2 strings. The subclass selects the SIP's units (pioneer_params.hpp); "p3at-sh" (an
  /// ARCOS P3-AT) reports mm and mm/s.
  std::string name = "pitchlab", type = "Pioneer", subtype = "p3at-sh";
};

class P2osEmulator final : public EmulatedDevice {
 public:
  /// `physics` empty: a unicycle integrating the command. Throws like EmulatedDevice, and
  /// std::invalid_argument for a subtype without known conversion factors.
  explicit P2osEmulator(const P2osEmulatorConfig& config, BasePhysics physics = {},
                        std::string link_path = "");
  ~P2osEmulator() override;
  /// True after OPEN until CLOSE.
  bool connected() const { return connected_; }
  /// True while motors are enabled.
  bool motors_enabled() const { return enabled_; }
  /// The wheel setpoint in force: forward [m/s], yaw rate [rad/s]; zero while the watchdog holds
  /// the motors (the client's command resumes with its next packet).
  std::pair<double, double> command() const {
    if (watchdog_stopped_) return {0.0, 0.0};
    return {v_mps_, omega_rps_};
  }
  /// Time since the client's last packet [s] (the watchdog fires at watchdog_s).
  double seconds_since_client_packet() const;

 private:
  void OnBytes(const std::uint8_t* bytes, std::size_t size) override;
  void OnIdle() override;
  void OnPowerOn() override;
  void Handle(const std::vector<std::uint8_t>& payload);
  void Command(double v_mps, double omega_rps);
  void Drive();  // the setpoint in force to the physics (zero while the watchdog holds)
  BaseState State();
  void StepBuiltIn(double now_s);
  bool Parked(const BaseState& s);
  void SendSip();

  P2osEmulatorConfig config_;
  PioneerParams params_;
  BasePhysics physics_;
  p2os::PacketReader reader_;
  int sync_stage_ = 0;  // next SYNC expected; 3 = synced
  std::atomic<bool> connected_{false}, enabled_{false};
  std::atomic<double> v_mps_{0.0}, omega_rps_{0.0};
  std::atomic<double> last_packet_s_{0.0};
  std::atomic<bool> watchdog_stopped_{false};  // motors held; v_mps_, omega_rps_ kept
  double next_sip_s_ = 0.0, last_step_s_ = 0.0;
  BaseState own_;  // built-in model state
  // Reported odometry: the physics' motion, without the creep of a parked base.
  BaseState last_;                                 // physics state at the previous SIP
  double x_m_ = 0.0, y_m_ = 0.0, yaw_rad_ = 0.0;   // since power-on / SETO
  bool holding_ = false;                           // parked: reported pose frozen
  double hold_left_m_ = 0.0, hold_right_m_ = 0.0;  // wheel travel when it parked
};

}  // namespace pitchlab::hw
