#pragma once
// The device side of a serial link on a pseudo-terminal: a thread that reads requests, a writer
// that hands each reply over whole when the line could have delivered its last byte, fault
// injection, unplug/replug and power off/on. The protocol state machines (LMS200, pitch unit,
// P2OS) derive from it.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace pitchlab::hw {

/// What goes wrong on the wire, applied to the device's outgoing messages.
struct FaultPlan {
  enum class Kind {
    kNone,
    kDrop,       ///< one random byte of a message is lost
    kFlip,       ///< one random bit of a message is inverted
    kDuplicate,  ///< one random byte of a message is sent twice
    kDelay,      ///< the message stalls `delay_ms` halfway through
    kSilent,     ///< nothing is sent (no ACK, no reply)
  };
  Kind kind = Kind::kNone;
  int messages = -1;         ///< how many of the next messages it hits; -1 = all of them
  double probability = 1.0;  ///< chance a message is hit [0, 1]
  int delay_ms = 300;        ///< stall for kDelay [ms]
  std::uint64_t seed = 1;    ///< which byte / bit is hit
};

/// Counters of what the emulator did.
struct DeviceStats {
  std::size_t requests = 0;       ///< well-formed requests handled
  std::size_t bad_requests = 0;   ///< malformed requests (CRC, framing) seen
  std::size_t messages_sent = 0;  ///< messages (ACK bytes, replies) put on the wire
  std::size_t faults = 0;         ///< messages a fault hit
};

/// A pseudo-terminal with a device behind it. Drivers open path(); the path is a symlink that
/// stays valid across Unplug()/Replug() (like a udev name), so a driver can reconnect.
class EmulatedDevice {
 public:
  /// Creates the pty and the symlink `link_path` (empty: a fresh folder TMPDIR/pitchlab-hw-*,
  /// /tmp without TMPDIR, removed with the device or when the pty cannot be made). Throws
  /// std::runtime_error naming the path when the pty or the link cannot be made.
  EmulatedDevice(std::string name, int baud, std::string link_path = "");
  virtual ~EmulatedDevice();
  EmulatedDevice(const EmulatedDevice&) = delete;
  EmulatedDevice& operator=(const EmulatedDevice&) = delete;

  /// The device path a driver opens (the stable symlink).
  const std::string& path() const { return link_path_; }
  /// Installs a fault plan (replaces the previous one).
  void SetFaults(const FaultPlan& plan);
  /// Closes the pty: the driver's reads fail with a hang-up, the path dangles.
  void Unplug();
  /// A fresh pty behind the same path; the device restarts (power-on behaviour).
  void Replug();
  bool plugged() const { return plugged_; }
  /// Supply off: the device reads and drops everything and sends nothing, the port stays open
  /// (a powered-down device behind a live serial line). On again: the power-on behaviour.
  void SetPowered(bool on);
  bool powered() const { return powered_; }
  /// Bytes the device sent that the driver has not read yet (the pty's input queue).
  std::size_t unread_bytes() const;
  /// Current line rate [bit/s].
  int baud() const { return baud_; }
  DeviceStats stats() const;

 protected:
  /// Starts the I/O thread; derived constructors call it last.
  void Start();
  /// Stops the I/O thread; derived destructors call it first.
  void Stop();
  /// Request bytes arrived (I/O thread).
  virtual void OnBytes(const std::uint8_t* bytes, std::size_t size) = 0;
  /// Called about every 5 ms on the I/O thread (streaming, watchdogs).
  virtual void OnIdle() {}
  /// Called on the I/O thread after Replug(): reset protocol state, send a power-on message.
  virtual void OnPowerOn() {}
  /// Sends one message through the fault plan (I/O thread): written in one call at the moment
  /// its last byte would have left a UART at the current rate (10 bits a byte, 8N1), so a client
  /// sees it whole and never earlier than the line allows. Its first byte leaves when the line
  /// is free and not before `not_before` (default: now); a streaming device passes the time its
  /// data was ready, so the emulator's own work between messages is not added to the line time
  /// (the device measures while its UART sends). Two messages never arrive closer together than
  /// the second one's wire time.
  void Send(const std::vector<std::uint8_t>& bytes,
            std::optional<std::chrono::steady_clock::time_point> not_before = std::nullopt);
  /// When the line will be free of everything sent so far (steady clock).
  std::chrono::steady_clock::time_point line_free_at() const { return line_free_at_; }
  /// Changes the rate the device speaks at from now on.
  void set_baud(int baud) { baud_ = baud; }
  /// True when the driver's port is set to the device's rate (a pty stores the termios speed);
  /// a real device would see only garbage otherwise.
  bool DriverBaudMatches() const;
  void CountRequest(bool well_formed);

 private:
  void OpenPty();
  void ClosePty();
  void Loop();
  void WriteAtLineRate(const std::uint8_t* bytes, std::size_t size,
                       std::chrono::steady_clock::time_point not_before);

  std::string name_;
  std::atomic<int> baud_;
  std::string link_path_;
  bool own_link_dir_ = false;
  std::atomic<int> master_{-1};
  int held_slave_ = -1;  // keeps the pty alive while no driver has it open
  std::atomic<bool> plugged_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> replugged_{false};
  std::atomic<bool> powered_{true};
  std::chrono::steady_clock::time_point line_free_at_{};  // I/O thread only
  std::chrono::steady_clock::time_point last_write_{};    // I/O thread only
  std::thread thread_;
  mutable std::mutex mutex_;  // guards plan_, rng_, stats_, the pty fds during (un)plug
  FaultPlan plan_;
  std::mt19937_64 rng_;
  DeviceStats stats_;
};

}  // namespace pitchlab::hw
