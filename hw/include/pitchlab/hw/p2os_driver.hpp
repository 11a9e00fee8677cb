#pragma once
// The Pioneer P3 driver behind the MobileBase seam: P2OS sync handshake, OPEN, ENABLE,
// VEL/RVEL, SIP decoding into Odometry with the conversion factors of the robot's subclass. A
// service thread keeps the link alive whatever the caller does (a 45 s scan included): it
// sends PULSE well inside the robot's watchdog and reads every SIP as it arrives.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "pitchlab/hw/p2os_protocol.hpp"
#include "pitchlab/hw/pioneer_params.hpp"
#include "pitchlab/hw/serial_port.hpp"
#include "pitchlab/sensors/mobile_base.hpp"

namespace pitchlab::hw {

struct P2osDriverConfig {
  std::string device;          ///< serial device
  int baud = 9600;             ///< [bit/s]
  double max_v_mps = 0.75;     ///< command clamp [m/s]
  double max_omega_rps = 1.7;  ///< command clamp [rad/s]
  int sip_timeout_ms = 500;    ///< no SIP for this long is a device fault [ms]
  int sync_attempts = 3;       ///< handshake rounds before giving up

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// MobileBase over P2OS.
class P2osDriver final : public sensors::MobileBase {
 public:
  /// Syncs, opens and enables the motors, then starts the service thread. Throws
  /// std::runtime_error naming the device and the handshake step that failed, or the robot
  /// subclass when its conversion factors are unknown.
  explicit P2osDriver(const P2osDriverConfig& config, ClockFn clock = {});
  /// Stops the service thread, the motors, and sends CLOSE.
  ~P2osDriver() override;
  [[nodiscard]] Result<sensors::Odometry> Drive(double v_mps, double omega_rps,
                                                double duration_s) override;
  /// The odometry of the first SIP after the call (kTimeout after sip_timeout_ms).
  [[nodiscard]] Result<sensors::Odometry> ReadOdometry() override;
  /// Robot name, type and subtype from the SYNC2 reply.
  const std::string& robot() const { return robot_; }
  /// The conversion factors of the robot's subclass.
  const PioneerParams& params() const { return params_; }
  std::size_t checksum_errors() const { return checksum_errors_; }

 private:
  Result<void> Handshake();
  Result<void> SyncOnce();
  Result<void> Send(const std::vector<std::uint8_t>& packet);
  Result<std::vector<std::uint8_t>> WaitPacket(bool (*wanted)(std::uint8_t),
                                               std::chrono::milliseconds timeout);
  void Integrate(const p2os::Sip& sip);
  void Service();
  /// Waits until `deadline` or until a SIP after number `after` arrived (`need_sip`); the
  /// service thread's error, a stop request or a silent robot end it early.
  Result<void> Wait(std::chrono::steady_clock::time_point deadline, std::uint64_t after,
                    bool need_sip);

  P2osDriverConfig config_;
  ClockFn clock_;
  std::unique_ptr<SerialPort> port_;
  p2os::PacketReader reader_;  // handshake, then the service thread only
  std::string robot_;
  PioneerParams params_;
  std::thread service_;
  std::atomic<bool> running_{false};
  std::atomic<std::size_t> checksum_errors_{0};
  std::mutex write_mutex_;                           // one packet on the wire at a time
  std::chrono::steady_clock::time_point last_sent_;  // under write_mutex_
  mutable std::mutex mutex_;                         // guards everything below
  std::condition_variable sip_arrived_;
  std::optional<p2os::Sip> last_sip_;
  std::uint64_t sips_ = 0;
  std::chrono::steady_clock::time_point last_sip_time_;
  std::optional<Error> error_;  // the service thread's: the port hung up
  double x_mm_ = 0.0, y_mm_ = 0.0;
  sensors::Odometry odometry_;
};

}  // namespace pitchlab::hw
