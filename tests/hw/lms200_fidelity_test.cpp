// The LMS200 emulator against what independent clients send, byte for byte (issue 17, items
// 1-4): reset, real-time scan indices, the 32-byte configuration block, mean values, sub-ranges
// and partial scans. Requests are written as literal bytes (CRC included, computed with the
// LMS2xx manual's routine) so a test fails if either the request or the reply is not what the
// telegram listing says. Where each behaviour is documented: docs/hardware_interop.md.

#include <gtest/gtest.h>

#include <vector>

#include "client_wire.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"

namespace pitchlab::hw {
namespace {

using namespace client;  // NOLINT: the shared client-side helpers

// Reads the next sicktoolbox message whose command is `command` (other telegrams skipped).
std::optional<Bytes> NextMessage(Wire& wire, std::uint8_t command,
                                 milliseconds timeout = kReplyTimeout) {
  const auto deadline = Clock::now() + timeout;
  while (auto payload = SicktoolboxMessage(wire, deadline)) {
    if ((*payload)[0] == command) return payload;
  }
  return std::nullopt;
}

// Writes `request` and returns the byte that comes first (the ACK 0x06 or the NAK 0x15).
std::optional<std::uint8_t> WriteAndReadAck(Wire& wire, const Bytes& request) {
  wire.Flush();
  wire.Write(request);
  return wire.Byte(Clock::now() + kReplyTimeout);
}

TEST(Lms200Reset, IsAcknowledgedWith91ThenThePowerOnTelegramComesAt9600) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  // Switch to 38400 first: the reset must bring the device back to its power-on rate.
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x40}));
  wire.SetBaud(38400);
  // 10: reset. The device acknowledges (06), answers 91 with status 0 at the rate in force ...
  ASSERT_EQ(WriteAndReadAck(wire, {0x02, 0x00, 0x01, 0x00, 0x10, 0x34, 0x12}), 0x06);
  const auto deadline = Clock::now() + kReplyTimeout;
  Bytes reply;
  for (int i = 0; i < 8; ++i) {
    const auto b = wire.Byte(deadline);
    ASSERT_TRUE(b) << "no reset acknowledgement";
    reply.push_back(*b);
  }
  EXPECT_EQ(reply, (Bytes{0x02, 0x80, 0x02, 0x00, 0x91, 0x00, 0x69, 0x30}));
  // ... then restarts at 9600 and sends its power-on telegram there (sicktoolbox waits 60 s).
  wire.SetBaud(9600);
  const auto power_on = NextMessage(wire, 0x90, milliseconds(3000));
  ASSERT_TRUE(power_on) << "no power-on telegram at 9600 after the reset";
  const std::string text(power_on->begin() + 1, power_on->end() - 1);
  EXPECT_EQ(text.rfind("LMS200;30106", 0), 0u) << text;
  EXPECT_FALSE(emulator.streaming());
}

// Installation mode, then `block` written with 77; returns the F7 payload.
std::optional<Bytes> Configure(Wire& wire, const Bytes& block) {
  const auto setup =
      SicktoolboxTransact(wire, {0x20, 0x00, 'S', 'I', 'C', 'K', '_', 'L', 'M', 'S'});
  EXPECT_TRUE(setup && (*setup)[1] == 0x00) << "installation mode refused";
  Bytes request = {0x77};
  request.insert(request.end(), block.begin(), block.end());
  return SicktoolboxTransact(wire, request, milliseconds(3000));  // CONFIG_MESSAGE_TIMEOUT
}

TEST(Lms200RealTimeIndices, EachStreamedScanCarriesTheMirrorsRevolutionCount) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x40}));
  wire.SetBaud(38400);
  // The block in force with block C = 0x02 (sicktoolbox SetSickAvailability(REAL_TIME_INDICES)).
  auto config = SicktoolboxTransact(wire, {0x74});
  ASSERT_TRUE(config);
  Bytes block(config->begin() + 1, config->end() - 1);
  ASSERT_EQ(block.size(), 34u);
  block[4] = 0x02;
  const auto written = Configure(wire, block);
  ASSERT_TRUE(written);
  ASSERT_EQ((*written)[1], 0x01) << "real-time indices refused";
  EXPECT_EQ((*written)[2 + 4], 0x02);
  // Stream (180 deg / 0.5 deg: 361 values). _parseSickScanProfileB0: count word, values, then
  // with real-time indices on one index byte, then the status byte.
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x24}));
  std::vector<int> indices;
  std::vector<Clock::time_point> arrivals;
  for (int scan = 0; scan < 3; ++scan) {
    const auto b0 = NextMessage(wire, 0xB0);
    ASSERT_TRUE(b0) << "no scan " << scan;
    arrivals.push_back(Clock::now());
    const int count = (*b0)[1] + 256 * ((*b0)[2] & 0x03);
    ASSERT_EQ(count, 361);
    ASSERT_EQ(b0->size(), 1 + 2 + 2 * 361 + 1 + 1u) << "no real-time index byte";
    EXPECT_EQ(b0->back(), 0x00);  // status: no error
    const int centre = (*b0)[3 + 2 * 180] + 256 * ((*b0)[4 + 2 * 180] & 0x1F);
    EXPECT_EQ(centre, 300);  // the flat wall 3 m ahead, in cm: the values are where they were
    indices.push_back((*b0)[3 + 2 * 361]);
  }
  // The index counts 75 Hz mirror revolutions: between two telegrams it advances by their
  // spacing x 75, give or take the arrival jitter of a loaded machine (50 ms = 4 revolutions).
  for (int i = 1; i < 3; ++i) {
    const double gap_s = std::chrono::duration<double>(arrivals[i] - arrivals[i - 1]).count();
    const int advanced = (indices[i] - indices[i - 1] + 256) % 256;
    EXPECT_GT(advanced, 0);
    EXPECT_NEAR(advanced, gap_s * 75.0, 4.0) << "gap " << gap_s << " s";
  }
  // pitchlab's own decoder reads the same telegram.
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x25}));
  ASSERT_EQ(WriteAndReadAck(wire, LmsRequest({0x30, 0x01})), 0x06);
  const auto single = NextMessage(wire, 0xB0);
  ASSERT_TRUE(single);
  lms200::Telegram t{0x80, 0xB0, Bytes(single->begin() + 1, single->end())};
  Result<lms200::MeasuredValues> mv = lms200::DecodeMeasuredValues(t);
  ASSERT_TRUE(mv) << mv.error().message;
  EXPECT_TRUE(mv->real_time_index.has_value());
  EXPECT_EQ(mv->values.size(), 361u);
}

TEST(Lms200RealTimeIndices, TheHighAvailabilityBitItCannotEmulateIsRefused) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  Bytes block(34, 0x00);
  block[4] = 0x01;  // SICK_FLAG_AVAILABILITY_HIGH
  const auto written = Configure(wire, block);
  ASSERT_TRUE(written);
  EXPECT_EQ((*written)[1], 0x00);      // refused ...
  EXPECT_EQ((*written)[2 + 4], 0x00);  // ... and the block in force says so
}

// ARIA's ArLMS2xx (STATE_SET_MODE) with 3 reflector bits and 1 mm units: blanking 0, peak
// threshold 70, fog 0, measuring mode 1, units 1, temporary field 0, subtractive 0, multiple
// evaluation 2, restart 2, restart time 0, contours A-C 15 x 0, pixel 0, single value 0,
// restart times B/C 0, one extra byte: 32 bytes.
const Bytes kAriaBlock = {0x00, 0x00, 0x46, 0x00, 0x00, 0x01, 0x01, 0x00, 0x00, 0x02, 0x02,
                          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};

TEST(Lms200ConfigBlock, The32ByteBlockIsAppliedAsAPrefixOfTheFullOne) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  ASSERT_EQ(kAriaBlock.size(), 32u);
  const auto written = Configure(wire, kAriaBlock);
  ASSERT_TRUE(written) << "no F7 to a 32-byte block";
  ASSERT_EQ(written->size(), 1 + 1 + 34 + 1u);
  EXPECT_EQ((*written)[1], 0x01);  // accepted
  EXPECT_EQ(Bytes(written->begin() + 2, written->begin() + 34), kAriaBlock);
  EXPECT_EQ((*written)[2 + 32], 0x00);  // the dazzling evaluation word stays as it was
  EXPECT_EQ(emulator.current().range_mode, sensors::Lms200RangeMode::kMm);
  const auto config = SicktoolboxTransact(wire, {0x74});
  ASSERT_TRUE(config);
  EXPECT_EQ(Bytes(config->begin() + 1, config->begin() + 33), kAriaBlock);
}

TEST(Lms200ConfigBlock, ALengthTheFamilyDoesNotUseIsNotAcknowledged) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x00, 'S', 'I', 'C', 'K', '_', 'L', 'M', 'S'}));
  Bytes request = {0x77};
  request.insert(request.end(), kAriaBlock.begin(), kAriaBlock.end() - 1);  // 31 bytes
  EXPECT_EQ(WriteAndReadAck(wire, LmsRequest(request)), 0x15);
}

TEST(Lms200ConfigBlock, ARIAsDefaultOneReflectorBitModeIsRefusedNotNaked) {
  // ARIA's default "1ref" writes measuring mode 5 (32 m range, reflector bit on top): values
  // the emulator cannot produce. F7 with status 0 (ARIA reads any F7 as done).
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  Bytes block = kAriaBlock;
  block[5] = 0x05;
  const auto written = Configure(wire, block);
  ASSERT_TRUE(written);
  EXPECT_EQ((*written)[1], 0x00);
  EXPECT_EQ(emulator.current().range_mode, sensors::Lms200RangeMode::kCm);
}

TEST(Lms200OutputModes, MeanOfFiveScansStreamsB6Telegrams) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x40}));
  wire.SetBaud(38400);
  // 20 26 05: the mean of 5 scans, streamed (sicktoolbox SetSickOpModeMonitorStreamMeanValues).
  ASSERT_EQ(WriteAndReadAck(wire, {0x02, 0x00, 0x03, 0x00, 0x20, 0x26, 0x05, 0x79, 0x3E}), 0x06);
  const auto switched = NextMessage(wire, 0xA0);
  ASSERT_TRUE(switched);
  EXPECT_EQ((*switched)[1], 0x00) << "mean values refused";
  EXPECT_TRUE(emulator.streaming());
  // _parseSickScanProfileB6: sample size, count word, values, status.
  const auto b6 = NextMessage(wire, 0xB6);
  ASSERT_TRUE(b6) << "no mean values streamed";
  EXPECT_EQ((*b6)[1], 5);
  const int count = (*b6)[2] + 256 * ((*b6)[3] & 0x03);
  ASSERT_EQ(count, 361);
  ASSERT_EQ(b6->size(), 1 + 1 + 2 + 2 * 361 + 1u);
  EXPECT_EQ((*b6)[4 + 2 * 180] + 256 * ((*b6)[5 + 2 * 180] & 0x1F), 300);  // 3 m in cm
  // Out of the listing's 2..250 samples: not possible.
  const auto refused = SicktoolboxTransact(wire, {0x20, 0x26, 0x01});
  ASSERT_TRUE(refused);
  EXPECT_EQ((*refused)[1], 0x02);
}

TEST(Lms200OutputModes, ASubrangeStreamsB7WithItsIndicesAndOnlyThoseValues) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  ASSERT_TRUE(SicktoolboxTransact(wire, {0x20, 0x40}));
  wire.SetBaud(38400);
  // 20 27 0001 000A: values 1..10 (sicktoolbox SetSickOpModeMonitorStreamValuesSubrange).
  ASSERT_EQ(WriteAndReadAck(
                wire, {0x02, 0x00, 0x06, 0x00, 0x20, 0x27, 0x01, 0x00, 0x0A, 0x00, 0x6C, 0xB7}),
            0x06);
  const auto switched = NextMessage(wire, 0xA0);
  ASSERT_TRUE(switched);
  EXPECT_EQ((*switched)[1], 0x00) << "sub-range refused";
  // _parseSickScanProfileB7: first, last (LE16), count word, values, status.
  const auto b7 = NextMessage(wire, 0xB7);
  ASSERT_TRUE(b7) << "no sub-range streamed";
  EXPECT_EQ(Le16(*b7, 1), 1);
  EXPECT_EQ(Le16(*b7, 3), 10);
  const int count = (*b7)[5] + 256 * ((*b7)[6] & 0x03);
  ASSERT_EQ(count, 10);
  ASSERT_EQ(b7->size(), 1 + 4 + 2 + 2 * 10 + 1u);
  // Beams 1..10 of 180 deg at 0.5 deg, -90 .. -85.5 deg, against the wall 3 m ahead: the
  // built-in wall returns nothing where cos < 0.05 (beams 1..6), else 3 m / cos in cm.
  for (int i = 0; i < 6; ++i) EXPECT_GE(Le16(*b7, 7 + 2 * i) & 0x1FFF, 8183) << i;
  EXPECT_EQ(Le16(*b7, 7 + 2 * 9) & 0x1FFF, 3824);  // 300 cm / cos(85.5 deg)
  // A range past the last value is not possible.
  const auto refused = SicktoolboxTransact(wire, {0x20, 0x27, 0x01, 0x00, 0x6A, 0x01});
  ASSERT_TRUE(refused);
  EXPECT_EQ((*refused)[1], 0x02);
}

TEST(Lms200OutputModes, ModesItDoesNotEmulateAreNotPossibleAndTheModeInForceStays) {
  // Documented as not emulated (docs/hardware_interop.md): A0 with 0x02, nothing streamed.
  // sicktoolbox's operating modes: 28 mean sub-range (BF), 29 values with field bits, 2A partial
  // scans, 2B range and reflectivity of partial scans, 2C minimum per segment, 2E navigation,
  // 50 range and reflectivity (LMS2x1-S14 only, C4).
  const Bytes requests[] = {
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x28, 0x38, 0x08},
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x29, 0x39, 0x08},
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x2A, 0x3A, 0x08},
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x2B, 0x3B, 0x08},
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x2C, 0x3C, 0x08},
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x2E, 0x3E, 0x08},
      {0x02, 0x00, 0x02, 0x00, 0x20, 0x50, 0x40, 0x08},
  };
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  for (const Bytes& request : requests) {
    SCOPED_TRACE(int(request[5]));
    ASSERT_EQ(WriteAndReadAck(wire, request), 0x06);
    const auto reply = NextMessage(wire, 0xA0);
    ASSERT_TRUE(reply);
    EXPECT_EQ(*reply, (Bytes{0xA0, 0x02, 0x00}));
    EXPECT_FALSE(emulator.streaming());
  }
}

TEST(Lms200Requests, RequestsOutsideTheEmulatedSetAreNotAcknowledged) {
  // 36 (not in the emulated set) and 30 with a sub-code other than 01 (one full scan): NAK.
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  EXPECT_EQ(WriteAndReadAck(wire, {0x02, 0x00, 0x01, 0x00, 0x36, 0x12, 0x12}), 0x15);
  EXPECT_EQ(WriteAndReadAck(wire, {0x02, 0x00, 0x02, 0x00, 0x30, 0x05, 0x35, 0x18}), 0x15);
  // 31 (status) with its CRC's low byte flipped: NAK, as the listing says for a CRC error.
  EXPECT_EQ(WriteAndReadAck(wire, LmsRequest({0x31})), 0x06);
  ASSERT_TRUE(NextMessage(wire, 0xB1));  // the status reply, before the next request
  Bytes corrupted = LmsRequest({0x31});
  corrupted[5] ^= 0xFF;
  EXPECT_EQ(WriteAndReadAck(wire, corrupted), 0x15);
}

// A header claiming 255 bytes (line noise, a driver killed mid-write) with a status request right
// behind it: the request's bytes are read as that telegram's, and nothing is answered. When the
// line has been quiet past the character timeout the partial telegram is gone: the next request
// is answered, and nothing stale comes with it (before, every later request was swallowed until
// 261 bytes had come, then all were answered at once).
TEST(Lms200Requests, ATelegramWhoseCharactersStopComingIsDroppedAndTheNextRequestIsAnswered) {
  Lms200Emulator emulator{Lms200EmulatorConfig{}};
  Wire wire(emulator.path(), 9600);
  Bytes noise = {0x02, 0x13, 0xFF, 0x00};
  const Bytes status = LmsRequest({0x31});
  noise.insert(noise.end(), status.begin(), status.end());
  wire.Write(noise);
  EXPECT_FALSE(wire.Byte(Clock::now() + milliseconds(300))) << "answered inside a false frame";
  EXPECT_EQ(WriteAndReadAck(wire, status), 0x06);
  const auto reply = NextMessage(wire, 0xB1);
  ASSERT_TRUE(reply);
  EXPECT_FALSE(wire.Byte(Clock::now() + milliseconds(300))) << "a stale reply followed";
}

}  // namespace
}  // namespace pitchlab::hw
