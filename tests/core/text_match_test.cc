#include "penumbra/core/text_match.h"

#include <gtest/gtest.h>

namespace penumbra {
namespace {

TEST(GlobMatchTest, StarsAndQuestionMarks) {
  EXPECT_TRUE(GlobMatch("go1/*_foot", "go1/FR_foot"));
  EXPECT_FALSE(GlobMatch("go1/*_foot", "go1/FR_calf"));
  EXPECT_TRUE(GlobMatch("rover/*", "rover/chassis"));
  EXPECT_FALSE(GlobMatch("rover/*", "arm/link"));
  EXPECT_TRUE(GlobMatch("*", ""));
  EXPECT_TRUE(GlobMatch("r?v*", "rover/chassis"));
  EXPECT_TRUE(GlobMatch("*wheel?", "rover/wheel3"));
  EXPECT_FALSE(GlobMatch("*wheel?", "rover/wheel"));
  EXPECT_TRUE(GlobMatch("a*b*c", "axxbyyc"));
  EXPECT_TRUE(GlobMatch("*a*b*", "xxaxxbxx"));
  EXPECT_FALSE(GlobMatch("room/floor", "room/floor2"));
  EXPECT_FALSE(GlobMatch("abc", "abcd"));
  EXPECT_FALSE(GlobMatch("Rover/*", "rover/chassis"));  // case-sensitive
}

TEST(ParseDecimalTest, AcceptsPlainDecimalsOnly) {
  EXPECT_EQ(ParseDecimal("1"), 1.0);
  EXPECT_EQ(ParseDecimal("-0.5"), -0.5);
  EXPECT_EQ(ParseDecimal("+2.5"), 2.5);
  EXPECT_EQ(ParseDecimal(".5"), 0.5);
  EXPECT_EQ(ParseDecimal("2."), 2.0);
  EXPECT_EQ(ParseDecimal("1e-3"), 1e-3);
  EXPECT_EQ(ParseDecimal("1E+2"), 100.0);
  for (const char* bad : {"", "+", "-", ".", "e5", "1e", "1e+", "0x10", "inf", "nan", "-inf", "+-1",
                          "-+1", "1e999", " 1", "1 ", "1,5", "1.2.3"})
    EXPECT_FALSE(ParseDecimal(bad).has_value()) << bad;
}

}  // namespace
}  // namespace penumbra
