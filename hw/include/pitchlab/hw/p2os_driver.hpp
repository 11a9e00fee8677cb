#pragma once
// The Pioneer P3 driver behind the MobileBase seam: P2OS sync handshake, OPEN, ENABLE,
// VEL/RVEL, keep-alive PULSEs, SIP decoding into Odometry.

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pitchlab/hw/p2os_protocol.hpp"
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
  /// Syncs, opens and enables the motors. Throws std::runtime_error naming the device and the
  /// handshake step that failed.
  explicit P2osDriver(const P2osDriverConfig& config, ClockFn clock = {});
  /// Stops the motors and sends CLOSE.
  ~P2osDriver() override;
  [[nodiscard]] Result<sensors::Odometry> Drive(double v_mps, double omega_rps,
                                                double duration_s) override;
  [[nodiscard]] Result<sensors::Odometry> ReadOdometry() override;
  /// Robot name, type and subtype from the SYNC2 reply.
  const std::string& robot() const { return robot_; }
  std::size_t checksum_errors() const { return reader_.checksum_errors(); }

 private:
  Result<void> Handshake();
  Result<void> Send(const std::vector<std::uint8_t>& packet);
  /// Reads packets until `deadline`, integrating SIPs; true when at least one SIP came.
  Result<bool> Pump(std::chrono::steady_clock::time_point deadline, bool stop_at_first_sip);
  Result<std::vector<std::uint8_t>> WaitPacket(std::uint8_t first_byte,
                                               std::chrono::milliseconds timeout);
  void Integrate(const p2os::Sip& sip);

  P2osDriverConfig config_;
  ClockFn clock_;
  std::unique_ptr<SerialPort> port_;
  p2os::PacketReader reader_;
  std::string robot_;
  std::optional<p2os::Sip> last_sip_;
  double x_mm_ = 0.0, y_mm_ = 0.0;
  sensors::Odometry odometry_;
  std::chrono::steady_clock::time_point last_pulse_;
};

}  // namespace pitchlab::hw
