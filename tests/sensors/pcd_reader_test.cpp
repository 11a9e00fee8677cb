// Our PCD data reader (sensors/src/pcd_data.cpp) on files made by hand, byte by byte: LZF's
// literal runs and overlapping back references, binary_compressed's field-by-field layout, and
// ascii data lines that are not what the header says. PCL's own writers are the peer in
// cloud_file_test and pcd_robustness_test.

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/sensors/scan_pcd.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::sensors {
namespace {

namespace fs = std::filesystem;

class PcdReader : public ::testing::Test {
 protected:
  // A file of `header` lines (FIELDS to POINTS) and `data` after "DATA <kind>\n".
  fs::path Write(const std::string& header, const std::string& kind, const std::string& data) {
    const fs::path file = dir_ / "cloud.pcd";
    std::ofstream(file, std::ios::binary) << "# .PCD v0.7\nVERSION 0.7\n"
                                          << header << "DATA " << kind << "\n"
                                          << data;
    return file;
  }
  // binary_compressed data: the two size words, then the LZF stream.
  static std::string Compressed(const std::vector<std::uint8_t>& lzf, std::uint32_t unpacked) {
    std::string data(8, '\0');
    const std::uint32_t packed = static_cast<std::uint32_t>(lzf.size());
    std::memcpy(&data[0], &packed, 4);
    std::memcpy(&data[4], &unpacked, 4);
    return data + std::string(lzf.begin(), lzf.end());
  }
  static std::vector<std::uint8_t> Bytes(std::initializer_list<float> values) {
    std::vector<std::uint8_t> out(values.size() * 4);
    std::memcpy(out.data(), values.begin(), out.size());
    return out;
  }

  static constexpr const char* kXyz2 =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";
  const test_support::ScopedTempDir dir_{"pcdreader"};
};

// Compressed, a field's values for every point lie together (x0 x1 y0 y1 z0 z1): one literal run
// of all 24 bytes reads as the points (1, 3, 5) and (2, 4, 6).
TEST_F(PcdReader, CompressedDataIsStoredFieldByField) {
  std::vector<std::uint8_t> lzf{23};  // a literal run of 23 + 1 bytes
  const std::vector<std::uint8_t> values = Bytes({1, 2, 3, 4, 5, 6});
  lzf.insert(lzf.end(), values.begin(), values.end());
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "binary_compressed", Compressed(lzf, 24)));
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->points.size(), 2u);
  EXPECT_EQ(scan->points[0].x, 1.0f);
  EXPECT_EQ(scan->points[0].y, 3.0f);
  EXPECT_EQ(scan->points[0].z, 5.0f);
  EXPECT_EQ(scan->points[1].x, 2.0f);
  EXPECT_EQ(scan->points[1].y, 4.0f);
  EXPECT_EQ(scan->points[1].z, 6.0f);
}

// A back reference copies from `distance` bytes back, overlapping what it writes: 4 literal bytes
// (1.0f) and a 20-byte copy from 4 back (length 7 + an extension byte 11, + 2) make six 1.0f.
TEST_F(PcdReader, AnOverlappingBackReferenceRepeatsWhatItCopies) {
  std::vector<std::uint8_t> lzf{3};  // a literal run of 4 bytes
  const std::vector<std::uint8_t> one = Bytes({1.0f});
  lzf.insert(lzf.end(), one.begin(), one.end());
  lzf.insert(lzf.end(), {0xE0, 11, 3});  // length 7 + 11 + 2 = 20, distance 3 + 1 = 4
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "binary_compressed", Compressed(lzf, 24)));
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->points.size(), 2u);
  for (const ScanPoint& p : scan->points) {
    EXPECT_EQ(p.x, 1.0f);
    EXPECT_EQ(p.y, 1.0f);
    EXPECT_EQ(p.z, 1.0f);
  }
}

TEST_F(PcdReader, ABackReferenceBeforeTheStartIsCorruptData) {
  const std::vector<std::uint8_t> lzf{0xE0, 11, 3};  // copies from 4 bytes before the first
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "binary_compressed", Compressed(lzf, 24)));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("cloud.pcd"), std::string::npos) << scan.error().message;
  EXPECT_NE(scan.error().message.find("does not decompress to 24 bytes"), std::string::npos)
      << scan.error().message;
}

TEST_F(PcdReader, CompressedDataShortOfItsSizeIsCorrupt) {
  std::vector<std::uint8_t> lzf{19};  // 20 of the 24 bytes
  lzf.resize(21, 0);
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "binary_compressed", Compressed(lzf, 24)));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("does not decompress"), std::string::npos)
      << scan.error().message;
}

// Ascii: a value that is no number is an error naming the line of the file and the value.
TEST_F(PcdReader, AnAsciiValueThatIsNoNumberNamesItsLine) {
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "ascii", "1 2 3\n1 two 3\n"));
  ASSERT_FALSE(scan);
  const std::string& m = scan.error().message;
  EXPECT_NE(m.find("cloud.pcd"), std::string::npos) << m;
  EXPECT_NE(m.find("line 13"), std::string::npos) << m;  // 11 header lines, DATA, then 2
  EXPECT_NE(m.find("'two'"), std::string::npos) << m;
}

TEST_F(PcdReader, AnAsciiLineWithTooFewValuesNamesItsLine) {
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "ascii", "1 2 3\n\n4 5\n"));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("line 14 has 2 values, its FIELDS hold 3"), std::string::npos)
      << scan.error().message;
}

// Ascii integers are checked against their field: 70000 is no U 2 value (ring), 1.5 no integer.
TEST_F(PcdReader, AnAsciiIntegerOutOfItsFieldsRangeIsAnError) {
  const std::string header =
      "FIELDS x y z ring\nSIZE 4 4 4 2\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\n"
      "POINTS 1\n";
  EXPECT_TRUE(ReadScanPcd(Write(header, "ascii", "1 2 3 65535\n")));
  for (const char* ring : {"70000", "-1", "1.5"}) {
    Result<Scan3D> scan = ReadScanPcd(Write(header, "ascii", std::string("1 2 3 ") + ring + "\n"));
    ASSERT_FALSE(scan) << ring;
    EXPECT_NE(scan.error().message.find("field 'ring'"), std::string::npos) << scan.error().message;
  }
}

TEST_F(PcdReader, AnAsciiNanIsAMissingReturn) {
  Result<Scan3D> scan = ReadScanPcd(Write(kXyz2, "ascii", "nan nan nan\n1 2 3\n"));
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_EQ(scan->points.size(), 1u);
  EXPECT_EQ(scan->no_returns, 1u);
}

// A field no PCD writer makes (a 2-byte float) is an error naming it, not a misread record.
TEST_F(PcdReader, AFieldOfAnUnknownSizeIsAnErrorNamingIt) {
  const std::string header =
      "FIELDS x y z w\nSIZE 4 4 4 2\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n";
  Result<Scan3D> scan = ReadScanPcd(Write(header, "binary", std::string(14, '\0')));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("field 'w' of TYPE F, SIZE 2"), std::string::npos)
      << scan.error().message;
}

// Found by fuzzing (a DATA line of no known encoding, at the end of the file without a newline):
// it had read as ascii data starting at an offset of -1, and thrown std::length_error.
TEST_F(PcdReader, ADataLineOfNoKnownEncodingIsAnErrorNamingIt) {
  const fs::path file = dir_ / "cloud.pcd";
  std::ofstream(file, std::ios::binary) << "VERSION 0.7\n" << kXyz2 << "DATA binary_compress\x9b";
  Result<Scan3D> scan = ReadScanPcd(file.string());
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("is none of ascii, binary, binary_compressed"),
            std::string::npos)
      << scan.error().message;
}

TEST_F(PcdReader, AFileEndingWithItsDataLineHoldsNoPoints) {
  const fs::path file = dir_ / "cloud.pcd";
  std::ofstream(file, std::ios::binary) << "VERSION 0.7\n" << kXyz2 << "DATA ascii";
  Result<Scan3D> scan = ReadScanPcd(file.string());
  ASSERT_FALSE(scan);  // two points promised, none there
  EXPECT_NE(scan.error().message.find("cloud.pcd"), std::string::npos) << scan.error().message;
}

// LZF makes at most 88 bytes of one (264 of a 3-byte back reference): a header whose points need
// more from the stream it has is refused before anything that size is allocated.
TEST_F(PcdReader, AnUncompressedSizeBeyondWhatLzfMakesIsRefused) {
  const std::string header =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100\nHEIGHT 1\nPOINTS 100\n";
  Result<Scan3D> scan =
      ReadScanPcd(Write(header, "binary_compressed", Compressed({3, 0, 0, 0, 0}, 1200)));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("more than LZF makes of 5"), std::string::npos)
      << scan.error().message;
}

// A SIZE or COUNT beyond any writer's (here 1e12 values a point) is an error naming the field.
TEST_F(PcdReader, AnAbsurdCountIsAnErrorNamingTheField) {
  const std::string header =
      "FIELDS x y z h\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1e12\nWIDTH 1\nHEIGHT 1\n"
      "POINTS 1\n";
  Result<Scan3D> scan = ReadScanPcd(Write(header, "ascii", "1 2 3 4\n"));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("field 'h'"), std::string::npos) << scan.error().message;
}

// Fields with several values (COUNT 3) keep the record's layout: x y z after a 3-float normal.
TEST_F(PcdReader, AFieldOfSeveralValuesTakesItsWholeWidth) {
  const std::string header =
      "FIELDS normal x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 3 1 1 1\nWIDTH 1\nHEIGHT 1\n"
      "POINTS 1\n";
  const std::vector<std::uint8_t> record = Bytes({0, 0, 1, 7, 8, 9});
  Result<Scan3D> binary =
      ReadScanPcd(Write(header, "binary", std::string(record.begin(), record.end())));
  ASSERT_TRUE(binary) << binary.error().message;
  ASSERT_EQ(binary->points.size(), 1u);
  EXPECT_EQ(binary->points[0].x, 7.0f);
  EXPECT_EQ(binary->points[0].z, 9.0f);
  Result<Scan3D> ascii = ReadScanPcd(Write(header, "ascii", "0 0 1 7 8 9\n"));
  ASSERT_TRUE(ascii) << ascii.error().message;
  EXPECT_EQ(ascii->points[0].y, 8.0f);
}

// Damaged files (a few bytes changed anywhere, header included) are read or refused with an
// error naming the file: never a crash or a read out of bounds (run under ASan by
// scripts/sanitize.sh). 400 draws per encoding, seeded; a compressed file of 50 points whose
// LZF stream holds literal runs and back references alike.
TEST_F(PcdReader, RandomlyDamagedFilesAreReadOrRefused) {
  // The stream made op by op with what it decompresses to: literal runs of 8 bytes (floats
  // 0..6) and, between them, 12-byte copies from 8 bytes back (ctrl 0xE0, 3 more, distance 7+1).
  std::vector<std::uint8_t> lzf, unpacked;
  while (unpacked.size() < 600) {
    const std::size_t n = std::min<std::size_t>(8, 600 - unpacked.size());
    lzf.push_back(static_cast<std::uint8_t>(n - 1));
    for (std::size_t k = 0; k < n; k += 4) {
      const std::vector<std::uint8_t> v = Bytes({static_cast<float>(unpacked.size() / 4 % 7)});
      lzf.insert(lzf.end(), v.begin(), v.end());
      unpacked.insert(unpacked.end(), v.begin(), v.end());
    }
    if (unpacked.size() + 12 <= 600) {
      lzf.insert(lzf.end(), {0xE0, 3, 7});
      for (int k = 0; k < 12; ++k) unpacked.push_back(unpacked[unpacked.size() - 8]);
    }
  }
  const std::string header50 =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 50\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 50\n";
  std::string ascii;
  for (int i = 0; i < 50; ++i) ascii += std::to_string(i) + " " + std::to_string(i % 7) + " 1\n";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"binary_compressed", Compressed(lzf, static_cast<std::uint32_t>(unpacked.size()))},
      {"binary", std::string(unpacked.begin(), unpacked.end())},
      {"ascii", ascii}};
  std::uint64_t state = 88172645463325252ull;  // xorshift64
  const auto next = [&state] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
  };
  for (const auto& [kind, data] : files) {
    const fs::path file = Write(header50, kind, data);
    Result<Scan3D> intact = ReadScanPcd(file);
    ASSERT_TRUE(intact) << kind << ": " << intact.error().message;
    ASSERT_EQ(intact->points.size(), 50u) << kind;
    std::ifstream in(file, std::ios::binary);
    const std::string bytes(std::istreambuf_iterator<char>(in), {});
    int refused = 0;
    for (int draw = 0; draw < 400; ++draw) {
      std::string damaged = bytes;
      for (int k = 1 + static_cast<int>(next() % 3); k > 0; --k) {
        damaged[next() % damaged.size()] = static_cast<char>(next() & 0xff);
      }
      std::ofstream(file, std::ios::binary | std::ios::trunc) << damaged;
      Result<Scan3D> scan = ReadScanPcd(file.string());
      if (!scan) {
        ++refused;
        EXPECT_NE(scan.error().message.find("cloud.pcd"), std::string::npos)
            << scan.error().message;
      }
    }
    EXPECT_GT(refused, 0) << kind;  // the damage reached what is checked
  }
}

}  // namespace
}  // namespace pitchlab::sensors
