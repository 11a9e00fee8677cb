// Streamed scans at 9600 baud under full CPU load (issue 17, item 5): sicktoolbox allows 35 ms
// between the bytes of a telegram (DEFAULT_SICK_LMS_2XX_SICK_BYTE_TIMEOUT) and waits 1 s for
// the next scan (GetSickScan's message timeout). A 401-value telegram takes 812 bytes x 10 bits
// / 9600 = 0.846 s on the wire, so both bounds are tight enough to catch a stalled writer and
// loose enough for a loaded 2-core machine.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <thread>
#include <vector>

#include "client_wire.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"

namespace pitchlab::hw {
namespace {

using namespace client;  // NOLINT: the shared client-side helpers

constexpr milliseconds kByteTimeout{35};    // sicktoolbox: between bytes of one telegram
constexpr milliseconds kScanTimeout{1000};  // sicktoolbox GetSickScan: the next scan
constexpr int kScans = 5;

// One busy thread per core, like `stress --cpu N`, for the lifetime of the object.
class CpuHog {
 public:
  CpuHog() {
    const unsigned cores = std::max(2u, std::thread::hardware_concurrency());
    for (unsigned i = 0; i < cores; ++i) {
      threads_.emplace_back([this] {
        volatile std::uint64_t x = 0;
        while (running_) x = x + 1;
      });
    }
  }
  ~CpuHog() {
    running_ = false;
    for (auto& t : threads_) t.join();
  }

 private:
  std::atomic<bool> running_{true};
  std::vector<std::thread> threads_;
};

struct Timed {
  std::uint8_t byte;
  Clock::time_point at;
};

// Every byte the port delivers until `deadline`, stamped when read.
std::vector<Timed> Record(SerialPort& port, Clock::time_point deadline) {
  std::vector<Timed> out;
  std::uint8_t buffer[1024];
  for (;;) {
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return out;
    Result<std::size_t> n = port.Read(buffer, sizeof(buffer), left);
    const auto now = Clock::now();
    if (n) {
      for (std::size_t i = 0; i < *n; ++i) out.push_back({buffer[i], now});
    }
  }
}

struct ScanTiming {
  bool complete = false;          // CRC right, 401 values
  milliseconds worst_gap{0};      // longest pause between two bytes of the telegram
  Clock::time_point first, last;  // its first and last byte
};

// The B0 telegrams in `bytes` as sicktoolbox frames them (02 80, LEN, payload, CRC).
std::vector<ScanTiming> Scans(const std::vector<Timed>& bytes) {
  std::vector<ScanTiming> scans;
  for (std::size_t i = 0; i + 4 < bytes.size(); ++i) {
    if (bytes[i].byte != 0x02 || bytes[i + 1].byte != 0x80 || bytes[i + 4].byte != 0xB0) continue;
    const std::size_t length = bytes[i + 2].byte | (bytes[i + 3].byte << 8);
    const std::size_t total = 4 + length + 2;
    if (i + total > bytes.size()) break;
    ScanTiming s;
    Bytes frame;
    for (std::size_t k = i; k < i + total; ++k) {
      frame.push_back(bytes[k].byte);
      if (k > i) {
        s.worst_gap = std::max(
            s.worst_gap, std::chrono::duration_cast<milliseconds>(bytes[k].at - bytes[k - 1].at));
      }
    }
    const int count = frame[5] + 256 * (frame[6] & 0x03);
    s.complete = lms200::Crc16(frame.data(), 4 + length) == Le16(frame, 4 + length) &&
                 count == 401 && length == 1 + 2 + 2 * 401 + 1;
    s.first = bytes[i].at;
    s.last = bytes[i + total - 1].at;
    scans.push_back(s);
    i += total - 1;
  }
  return scans;
}

TEST(Lms200StreamTiming, A401ValueScanAt9600ArrivesWholeAndInTimeUnderFullCpuLoad) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  CpuHog hog;
  Clock::time_point streaming_since;
  {
    Wire wire(emulator.path(), 9600);
    // 100 deg / 0.25 deg: 401 values, four interlaced sweeps; then stream.
    const auto variant = SicktoolboxTransact(wire, {0x3B, 0x64, 0x00, 0x19, 0x00});
    ASSERT_TRUE(variant && (*variant)[1] == 0x01);
    const auto started = SicktoolboxTransact(wire, {0x20, 0x24});
    ASSERT_TRUE(started && (*started)[1] == 0x00);
    streaming_since = Clock::now();
  }
  // The stream is read with timestamps on a port of its own (the first scan is ~0.85 s away).
  SerialPort port(emulator.path(), 9600);
  const std::vector<Timed> bytes =
      Record(port, streaming_since + (kScans + 1) * std::chrono::milliseconds(900));
  std::vector<ScanTiming> scans = Scans(bytes);
  ASSERT_GE(scans.size(), std::size_t(kScans)) << "scans received: " << scans.size();
  Clock::time_point previous = streaming_since;
  int complete = 0;
  milliseconds worst_gap{0}, worst_interval{0};
  for (int k = 0; k < kScans; ++k) {
    complete += scans[k].complete;
    worst_gap = std::max(worst_gap, scans[k].worst_gap);
    worst_interval = std::max(worst_interval,
                              std::chrono::duration_cast<milliseconds>(scans[k].last - previous));
    EXPECT_TRUE(scans[k].complete) << "scan " << k;
    EXPECT_LE(scans[k].worst_gap, kByteTimeout) << "scan " << k;
    EXPECT_LE(scans[k].last - previous, kScanTimeout)
        << "scan " << k << " after "
        << std::chrono::duration_cast<milliseconds>(scans[k].last - previous).count() << " ms";
    previous = scans[k].last;
  }
  std::printf(
      "streamed 401-value scans at 9600 under load: %d/%d complete, worst gap %lld ms, "
      "worst scan-to-scan %lld ms\n",
      complete, kScans, static_cast<long long>(worst_gap.count()),
      static_cast<long long>(worst_interval.count()));
}

}  // namespace
}  // namespace pitchlab::hw
