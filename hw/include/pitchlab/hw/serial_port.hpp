#pragma once
// A POSIX serial port in raw 8N1 mode: the byte pipe under every driver in hw/.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::hw {

/// A clock for stamps [s]; the drivers default to std::chrono::steady_clock.
using ClockFn = std::function<double()>;

/// True for the rates the devices speak: 9600, 19200, 38400, 115200, 500000 [bit/s].
bool IsSupportedBaud(int baud);

/// Wire time of `bytes` bytes at `baud` with 8N1 framing (10 bits a byte) [s].
double WireTime(std::size_t bytes, int baud);

/// Raw 8N1 port, no flow control, reads with poll() timeouts. Not thread-safe.
class SerialPort {
 public:
  /// Opens `device` at `baud`. Throws std::invalid_argument on an unsupported rate and
  /// std::runtime_error naming the device and the system error when it cannot be opened.
  SerialPort(std::string device, int baud);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Changes the line rate (500000 via the standard B500000). kInvalidArgument / kDevice.
  [[nodiscard]] Result<void> SetBaud(int baud);
  /// Writes all bytes into the port; kDevice when the port is gone.
  [[nodiscard]] Result<void> Write(const std::vector<std::uint8_t>& bytes);
  /// Reads up to `max` bytes, waiting at most `timeout` for the first; kTimeout when none came,
  /// kDevice when the device hung up (unplugged) or the port is closed.
  [[nodiscard]] Result<std::size_t> Read(std::uint8_t* buffer, std::size_t max,
                                         std::chrono::milliseconds timeout);
  /// Discards unread input.
  void DiscardInput();
  /// Closes and opens the device path again at the current rate (reconnect after an unplug).
  [[nodiscard]] Result<void> Reopen();
  /// Closes the port; Read/Write then fail with kDevice until Reopen().
  void Close();

  bool is_open() const { return fd_ >= 0; }
  const std::string& device() const { return device_; }
  int baud() const { return baud_; }

 private:
  Result<void> OpenAndConfigure();

  std::string device_;
  int baud_;
  int fd_ = -1;
};

}  // namespace pitchlab::hw
