#pragma once
// The SICK LMS200 serial driver behind the LineScanner seam: finds the device's rate, switches
// to the configured one, sets variant and range mode, requests single scans (or reads the
// continuous stream), and never hands on a line that failed any check.

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "pitchlab/hw/lms200_protocol.hpp"
#include "pitchlab/hw/serial_port.hpp"
#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/scan_source.hpp"

namespace pitchlab::hw {

struct Lms200DriverConfig {
  std::string device;          ///< serial device, e.g. /dev/ttyUSB0
  sensors::Lms200Config lms;   ///< variant, range mode and target `baud` (noise fields unused)
  int reply_timeout_ms = 500;  ///< ACK / short reply wait [ms]
  int retries = 3;             ///< attempts per request before giving up
  int reconnects = 2;          ///< reopen attempts when the device hangs up
  bool continuous = false;     ///< stream (mode 0x24) instead of one request per line

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// What the driver skipped, retried and recovered from.
struct Lms200DriverStats {
  lms200::ReaderStats reader;      ///< telegrams, ACK/NAK, CRC errors, garbage
  std::size_t retries = 0;         ///< requests sent again
  std::size_t reconnects = 0;      ///< successful reopen + re-initialise
  std::size_t rejected_lines = 0;  ///< measured-value replies that failed a check
};

/// LineScanner over a serial LMS200.
class Lms200Driver final : public sensors::LineScanner {
 public:
  /// Opens and initialises the device. Throws std::runtime_error naming the device and what
  /// failed (no answer at any rate, variant or range mode refused) and std::invalid_argument on
  /// a bad config.
  explicit Lms200Driver(const Lms200DriverConfig& config, ClockFn clock = {});
  ~Lms200Driver() override;

  /// One full line with its stamp (pitch left 0). Retries on NAK, CRC errors, garbage or a lost
  /// reply; reconnects after a hang-up; kTimeout / kDevice / kProtocol when all attempts failed.
  [[nodiscard]] Result<sensors::LaserLine> NextLine(std::chrono::milliseconds timeout) override;
  /// Probes the rate, switches baud, sets variant, range mode and output mode.
  [[nodiscard]] Result<void> Initialize();
  /// The device's type string (e.g. "LMS200;30106").
  const std::string& type() const { return type_; }
  const Lms200DriverStats& stats() const;
  const sensors::Lms200Model& model() const { return model_; }

 private:
  Result<lms200::Telegram> Transact(const lms200::Telegram& request,
                                    std::chrono::milliseconds timeout, int attempts = 0);
  Result<lms200::Telegram> WaitFor(std::uint8_t reply_command, bool need_ack,
                                   std::chrono::steady_clock::time_point deadline);
  Result<int> ProbeBaud();
  Result<void> SwitchBaud(int baud);
  Result<void> SetVariant();
  Result<void> SetRangeMode();
  Result<sensors::LaserLine> ToLine(const lms200::Telegram& reply, double stamp_s);
  Result<void> Reconnect();

  Lms200DriverConfig config_;
  ClockFn clock_;
  sensors::Lms200Model model_;
  std::unique_ptr<SerialPort> port_;
  lms200::TelegramReader reader_;
  mutable Lms200DriverStats stats_;
  std::string type_;
};

}  // namespace pitchlab::hw
