#pragma once
// The client's end of a serial line for the interoperability tests: raw bytes with deadlines,
// and the LMS2xx framing as sicktoolbox reads it (docs/hardware_interop.md). Shared by
// client_interop_test.cpp and the emulator fidelity tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pitchlab/hw/lms200_protocol.hpp"
#include "pitchlab/hw/serial_port.hpp"

namespace pitchlab::hw::client {

using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr double kPi = 3.14159265358979323846;
constexpr milliseconds kReplyTimeout{1000};  // the clients wait 1 s (Player) or more
constexpr milliseconds kWrongRateWait{250};  // shortened: the device ignores these requests

// The client's end of the line: raw bytes with deadlines.
class Wire {
 public:
  Wire(const std::string& device, int baud) : port_(device, baud) { port_.DiscardInput(); }
  void SetBaud(int baud) {
    ASSERT_TRUE(port_.SetBaud(baud));
    port_.DiscardInput();
  }
  void Write(const Bytes& bytes) { ASSERT_TRUE(port_.Write(bytes)); }
  void Flush() { port_.DiscardInput(); }
  // One byte, or nullopt at the deadline.
  std::optional<std::uint8_t> Byte(Clock::time_point deadline) {
    if (pos_ < pending_.size()) return pending_[pos_++];
    pending_.clear();
    pos_ = 0;
    for (;;) {
      const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return std::nullopt;
      std::uint8_t buffer[256];
      Result<std::size_t> n = port_.Read(buffer, sizeof(buffer), left);
      if (n && *n > 0) {
        pending_.assign(buffer, buffer + *n);
        pos_ = 1;
        return pending_[0];
      }
      if (!n && n.error().code == Error::Code::kDevice) return std::nullopt;
    }
  }

 private:
  SerialPort port_;
  Bytes pending_;
  std::size_t pos_ = 0;
};

// ---------------------------------------------------------------------------------------------
// SICK LMS2xx clients.

// A request as both LMS clients build it: STX, address 0, LEN = command + data (LE), the bytes,
// SICK's CRC (LE) over everything before it.
inline Bytes LmsRequest(const Bytes& command_and_data) {
  Bytes t;
  t.reserve(4 + command_and_data.size() + 2);  // sized up front: see pitch::Encode
  for (const std::uint8_t b :
       {std::uint8_t(0x02), std::uint8_t(0x00), std::uint8_t(command_and_data.size() & 0xFF),
        std::uint8_t(command_and_data.size() >> 8)}) {
    t.push_back(b);
  }
  t.insert(t.end(), command_and_data.begin(), command_and_data.end());
  const std::uint16_t crc = lms200::Crc16(t.data(), t.size());
  t.push_back(std::uint8_t(crc & 0xFF));
  t.push_back(std::uint8_t(crc >> 8));
  return t;
}

inline Bytes Text(const std::string& s) { return Bytes(s.begin(), s.end()); }
inline int Le16(const Bytes& b, std::size_t at) { return b[at] | (b[at + 1] << 8); }

// sicktoolbox (SickLMS2xxBufferMonitor::GetNextMessageFromDataStream): slide a two-byte window
// until STX + host address 0x80 (the ACK byte is skipped that way), read LEN (LE), LEN payload
// bytes (command .. status), the CRC, and compare it with the CRC of the rebuilt frame. A
// reply is the first message whose command is request + 0x80 (SickLMS2xx::_sendMessageAndGetReply).
inline std::optional<Bytes> SicktoolboxMessage(Wire& wire, Clock::time_point deadline) {
  for (;;) {
    std::uint8_t window[2] = {0, 0};
    while (window[0] != 0x02 || window[1] != 0x80) {
      const auto b = wire.Byte(deadline);
      if (!b) return std::nullopt;
      window[0] = window[1];
      window[1] = *b;
    }
    Bytes frame = {0x02, 0x80};
    for (int i = 0; i < 2; ++i) {
      const auto b = wire.Byte(deadline);
      if (!b) return std::nullopt;
      frame.push_back(*b);
    }
    const int length = Le16(frame, 2);
    if (length > 812) continue;  // MESSAGE_MAX_LENGTH: disregarded
    for (int i = 0; i < length + 2; ++i) {
      const auto b = wire.Byte(deadline);
      if (!b) return std::nullopt;
      frame.push_back(*b);
    }
    const std::uint16_t crc = lms200::Crc16(frame.data(), 4 + length);
    if (crc != Le16(frame, 4 + length)) continue;                 // bad checksum: message cleared
    return Bytes(frame.begin() + 4, frame.begin() + 4 + length);  // the payload
  }
}

inline std::optional<Bytes> SicktoolboxTransact(Wire& wire, const Bytes& request,
                                                milliseconds timeout = kReplyTimeout) {
  wire.Flush();  // _flushTerminalBuffer before every request
  wire.Write(LmsRequest(request));
  const auto deadline = Clock::now() + timeout;
  while (auto payload = SicktoolboxMessage(wire, deadline)) {
    if ((*payload)[0] == std::uint8_t(request[0] + 0x80)) return payload;
  }
  return std::nullopt;
}

// Polls `pred` every 5 ms until it holds or `timeout` passes.
template <typename Pred>
inline bool Eventually(Pred pred, milliseconds timeout = kReplyTimeout) {
  const auto deadline = Clock::now() + timeout;
  while (!pred()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return true;
}

}  // namespace pitchlab::hw::client
