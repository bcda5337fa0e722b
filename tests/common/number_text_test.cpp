// Numbers read from text, and the one wording of a bad one (server/common/number_text).  // SPDX-License-Identifier: Apache-2.0
#include "viscera/common/number_text.hpp"

#include <limits>
#include <string>

#include <gtest/gtest.h>

using viscera::common::outside;
using viscera::common::read_integer;
using viscera::common::read_number;

TEST(NumberText, ReadsTheWholeTextAsAFiniteNumberOrSaysWhyNot) {
  std::string why;
  EXPECT_EQ(read_number("-2.5e-3", &why), -2.5e-3);
  EXPECT_EQ(read_number("0.1"), 0.1);  // the nearest double, as a compiler reads the literal
  for (const char* bad : {"", "abc", "1.0x", " 1", "1 ", "0x10", "--1"}) {
    EXPECT_FALSE(read_number(bad, &why)) << bad;
    EXPECT_EQ(why, "'" + std::string(bad) + "' is not a number") << bad;
  }
  for (const char* bad : {"nan", "inf", "-inf", "1e400"}) {
    EXPECT_FALSE(read_number(bad, &why)) << bad;
    EXPECT_EQ(why, "'" + std::string(bad) + "' is not a finite number") << bad;
  }
  EXPECT_FALSE(read_number("\x1b[2J", &why));
  EXPECT_EQ(why, "'\\x1B[2J' is not a number") << "control characters are shown, never written to a terminal";
}

TEST(NumberText, ReadsWholeNumbersExactlyAndRefusesFractions) {
  std::string why;
  EXPECT_EQ(read_integer("9007199254740993", &why), 9007199254740993LL) << "beyond 2^53, exactly";
  EXPECT_EQ(read_integer("-12"), -12);
  EXPECT_EQ(read_integer("1e3"), 1000);
  EXPECT_EQ(read_integer("4.0"), 4);
  EXPECT_FALSE(read_integer("2.5", &why));
  EXPECT_EQ(why, "'2.5' is not a whole number");
  EXPECT_FALSE(read_integer("1e300", &why));
  EXPECT_EQ(why, "'1e300' is not a whole number") << "beyond what a long long holds";
  EXPECT_FALSE(read_integer("seven", &why));
  EXPECT_EQ(why, "'seven' is not a number");
}

TEST(NumberText, SaysARangeOneWay) {
  EXPECT_EQ(outside(-5.0, 1.0, 3600.0), "-5 is outside [1, 3600]");
  EXPECT_EQ(outside(2e9, 1.0, 1e9), "2e+09 is outside [1, 1e+09]");
  EXPECT_EQ(outside(-1LL, 0LL, 9007199254740991LL), "-1 is outside [0, 9007199254740991]");
}
