#include "pitchlab/hw/lms200_protocol.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace pitchlab::hw::lms200 {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(Lms200Crc, MatchesTheDocumentedModeSwitchTelegram) {
  const Bytes t = {0x02, 0x00, 0x02, 0x00, 0x20, 0x25};
  const std::uint16_t crc = Crc16(t.data(), t.size());
  EXPECT_EQ(crc & 0xFF, 0x35);
  EXPECT_EQ(crc >> 8, 0x08);
}

TEST(Lms200Crc, MatchesTheDocumentedScanRequestTelegram) {
  const Bytes t = {0x02, 0x00, 0x02, 0x00, 0x30, 0x01};
  const std::uint16_t crc = Crc16(t.data(), t.size());
  EXPECT_EQ(crc & 0xFF, 0x31);
  EXPECT_EQ(crc >> 8, 0x18);
}

TEST(Lms200Telegram, EncodesRequestsWithLengthAndLittleEndianCrc) {
  EXPECT_EQ(Encode(SwitchModeRequest(kModeOnRequest)),
            (Bytes{0x02, 0x00, 0x02, 0x00, 0x20, 0x25, 0x35, 0x08}));
  EXPECT_EQ(Encode(SingleScanRequest()), (Bytes{0x02, 0x00, 0x02, 0x00, 0x30, 0x01, 0x31, 0x18}));
}

TEST(Lms200Telegram, EveryRequestTheDriverSendsRoundTrips) {
  const std::vector<Telegram> requests = {SwitchModeRequest(kModeOnRequest),
                                          SwitchModeRequest(kModeContinuous),
                                          SwitchModeRequest(kModeBaud38400),
                                          SwitchModeRequest(kModeBaud500k),
                                          SetupModeRequest(),
                                          SingleScanRequest(),
                                          TypeRequest(),
                                          StatusRequest(),
                                          VariantRequest(180, 50),
                                          VariantRequest(100, 25),
                                          ConfigRequest(),
                                          ConfigureRequest(Bytes(kConfigBlockBytes, 0))};
  for (const Telegram& t : requests) {
    const Bytes bytes = Encode(t);
    ASSERT_EQ(bytes.size(), 4 + 1 + t.data.size() + 2);
    EXPECT_EQ(bytes[2] | (bytes[3] << 8), int(1 + t.data.size()));  // LEN = CMD + DATA
    Result<Telegram> back = Decode(bytes.data(), bytes.size());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(*back, t);
  }
}

TEST(Lms200Telegram, SetupModeCarriesThePassword) {
  const Telegram t = SetupModeRequest();
  EXPECT_EQ(std::string(t.data.begin() + 1, t.data.end()), "SICK_LMS");
  EXPECT_EQ(t.data[0], 0x00);
}

TEST(Lms200Telegram, VariantRequestIsLittleEndianAngleAndResolution) {
  EXPECT_EQ(VariantRequest(180, 50).data, (Bytes{0xB4, 0x00, 0x32, 0x00}));
  EXPECT_EQ(VariantRequest(100, 25).data, (Bytes{0x64, 0x00, 0x19, 0x00}));
}

TEST(Lms200Telegram, DecodeRejectsBadCrcLengthAndStx) {
  Bytes good = Encode(SingleScanRequest());
  Bytes bad_crc = good;
  bad_crc.back() ^= 0x01;
  EXPECT_FALSE(Decode(bad_crc.data(), bad_crc.size()));
  Bytes bad_stx = good;
  bad_stx[0] = 0x03;
  EXPECT_FALSE(Decode(bad_stx.data(), bad_stx.size()));
  EXPECT_FALSE(Decode(good.data(), good.size() - 1));
  EXPECT_FALSE(Decode(good.data(), 3));
}

TEST(Lms200Telegram, BaudCodesAreTheManuals) {
  EXPECT_EQ(BaudModeCode(9600), 0x42);
  EXPECT_EQ(BaudModeCode(19200), 0x41);
  EXPECT_EQ(BaudModeCode(38400), 0x40);
  EXPECT_EQ(BaudModeCode(500000), 0x48);
  EXPECT_FALSE(BaudModeCode(115200));
}

TEST(Lms200MeasuredValues, KnownReplyDecodesWithUnitBitsAndSpecialCodes) {
  // 4 values, mm units (bit 14), status 0x10 (pollution bit is not a fault code).
  const Telegram reply{
      kReplyAddress, 0xB0, {0x04, 0x40, 0xE8, 0x03, 0xFF, 0x1F, 0xFE, 0x1F, 0xF7, 0x1F, 0x10}};
  Result<MeasuredValues> mv = DecodeMeasuredValues(reply);
  ASSERT_TRUE(mv) << mv.error().message;
  EXPECT_EQ(mv->units, Units::kMm);
  EXPECT_EQ(mv->values, (std::vector<std::uint16_t>{1000, 8191, 8190, 8183}));
  EXPECT_EQ(mv->status, 0x10);
  auto [r0, s0] = DecodeReading(mv->values[0], mv->units);
  EXPECT_FLOAT_EQ(r0, 1.0f);
  EXPECT_EQ(s0, sensors::ReadingStatus::kValid);
  EXPECT_EQ(DecodeReading(8191, Units::kMm).second, sensors::ReadingStatus::kNoReturn);
  EXPECT_EQ(DecodeReading(8190, Units::kCm).second, sensors::ReadingStatus::kDazzled);
  EXPECT_EQ(DecodeReading(8183, Units::kCm).second, sensors::ReadingStatus::kOverRange);
  EXPECT_TRUE(std::isnan(DecodeReading(8191, Units::kCm).first));
  EXPECT_FLOAT_EQ(DecodeReading(1234, Units::kCm).first, 12.34f);
}

TEST(Lms200MeasuredValues, FlagBitsAboveThirteenAreStripped) {
  const Telegram reply{kReplyAddress, 0xB0, {0x01, 0x00, 0x64, 0xE0, 0x00}};
  Result<MeasuredValues> mv = DecodeMeasuredValues(reply);
  ASSERT_TRUE(mv);
  EXPECT_EQ(mv->values[0], 100);
  EXPECT_EQ(mv->units, Units::kCm);
}

TEST(Lms200MeasuredValues, CountThatDisagreesWithTheLengthIsRejected) {
  Telegram reply{kReplyAddress, 0xB0, {0x05, 0x00, 0x01, 0x00, 0x00}};
  EXPECT_FALSE(DecodeMeasuredValues(reply));
  reply.command = 0xB1;
  EXPECT_FALSE(DecodeMeasuredValues(reply));
}

TEST(Lms200MeasuredValues, EncodeDecodeRoundTripsEveryStatus) {
  for (Units units : {Units::kCm, Units::kMm}) {
    MeasuredValues mv;
    mv.units = units;
    mv.values = {0, 1, 4000, 8182, kCodeNoReturn, kCodeDazzled, kCodeOverRange};
    Result<MeasuredValues> back = DecodeMeasuredValues(EncodeMeasuredValues(mv));
    ASSERT_TRUE(back);
    EXPECT_EQ(back->values, mv.values);
    EXPECT_EQ(back->units, units);
  }
  EXPECT_EQ(EncodeReading(8.19f, sensors::ReadingStatus::kValid, Units::kMm), kCodeOverRange);
  EXPECT_EQ(EncodeReading(2.5f, sensors::ReadingStatus::kValid, Units::kCm), 250);
  EXPECT_EQ(EncodeReading(NAN, sensors::ReadingStatus::kNoReturn, Units::kCm), kCodeNoReturn);
}

// The reader, fed byte sequences a noisy line produces.
class ReaderTest : public ::testing::Test {
 protected:
  void Feed(const Bytes& b) { reader_.Feed(b.data(), b.size()); }
  std::vector<ReaderEvent> Drain() {
    std::vector<ReaderEvent> out;
    while (auto e = reader_.Next()) out.push_back(*e);
    return out;
  }
  Bytes Reply() const { return Encode(Telegram{kReplyAddress, 0xA0, {0x00, 0x10}}); }
  TelegramReader reader_;
};

TEST_F(ReaderTest, AckThenReplyAreTwoEvents) {
  Bytes b = {kAck};
  const Bytes r = Reply();
  b.insert(b.end(), r.begin(), r.end());
  Feed(b);
  auto events = Drain();
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, ReaderEvent::Kind::kAck);
  EXPECT_EQ(events[1].kind, ReaderEvent::Kind::kTelegram);
  EXPECT_EQ(events[1].telegram.command, 0xA0);
}

TEST_F(ReaderTest, GarbageBeforeAndBetweenTelegramsIsSkippedAndCounted) {
  Bytes b = {0x55, 0xAA, 0x02, 0x01};  // includes a false STX with a request address
  const Bytes r = Reply();
  b.insert(b.end(), r.begin(), r.end());
  b.insert(b.end(), {0x99, 0x98});
  b.insert(b.end(), r.begin(), r.end());
  Feed(b);
  auto events = Drain();
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(reader_.stats().telegrams, 2u);
  EXPECT_EQ(reader_.stats().garbage_bytes, 6u);
}

TEST_F(ReaderTest, PartialTelegramWaitsForTheRest) {
  const Bytes r = Reply();
  for (std::size_t i = 0; i + 1 < r.size(); ++i) {
    reader_.Feed(&r[i], 1);
    EXPECT_FALSE(reader_.Next());
  }
  reader_.Feed(&r.back(), 1);
  auto e = reader_.Next();
  ASSERT_TRUE(e);
  EXPECT_EQ(e->telegram.command, 0xA0);
}

TEST_F(ReaderTest, CrcErrorIsCountedAndTheNextTelegramStillFound) {
  Bytes bad = Reply();
  bad[5] ^= 0x04;
  const Bytes good = Reply();
  Bytes b = bad;
  b.insert(b.end(), good.begin(), good.end());
  Feed(b);
  auto events = Drain();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ReaderEvent::Kind::kTelegram);
  EXPECT_EQ(reader_.stats().crc_errors, 1u);
}

TEST_F(ReaderTest, TelegramHiddenBehindAFalseHeaderIsFound) {
  // A false STX whose length swallows the real telegram: dropping only the STX recovers it.
  Bytes b = {0x02, 0x80, 0x0A, 0x00};
  const Bytes r = Reply();
  b.insert(b.end(), r.begin(), r.end());
  b.insert(b.end(), 8, 0x00);
  Feed(b);
  auto events = Drain();
  bool found = false;
  for (const auto& e : events) found |= e.kind == ReaderEvent::Kind::kTelegram;
  EXPECT_TRUE(found);
}

TEST_F(ReaderTest, NakIsReportedAndCounted) {
  Feed({kNak});
  auto events = Drain();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ReaderEvent::Kind::kNak);
  EXPECT_EQ(reader_.stats().naks, 1u);
}

TEST_F(ReaderTest, AbsurdLengthIsSkippedNotAwaited) {
  Bytes b = {0x02, 0x80, 0xFF, 0xFF};
  const Bytes r = Reply();
  b.insert(b.end(), r.begin(), r.end());
  Feed(b);
  auto events = Drain();
  ASSERT_EQ(events.size(), 1u);
}

}  // namespace
}  // namespace pitchlab::hw::lms200
