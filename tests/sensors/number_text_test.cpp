// Numbers in messages (number_text.hpp): as people write them, not std::to_string's six decimals.

#include "pitchlab/sensors/number_text.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace pitchlab {
namespace {

TEST(NumberText, WritesNumbersWithoutTrailingZeros) {
  EXPECT_EQ(NumberText(0.1), "0.1");
  EXPECT_EQ(NumberText(4.0), "4");
  EXPECT_EQ(NumberText(-12.5), "-12.5");
  EXPECT_EQ(NumberText(93.1234567), "93.1235");  // six significant digits
  EXPECT_EQ(NumberText(1e-7), "1e-07");
  EXPECT_EQ(NumberText(2.5e9), "2.5e+09");
}

TEST(NumberText, SaysWhatIsNotANumber) {
  EXPECT_EQ(NumberText(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(NumberText(-std::numeric_limits<double>::infinity()), "-inf");
}

}  // namespace
}  // namespace pitchlab
