#include <gtest/gtest.h>

#include "io/size.h"

namespace skybake {
namespace {

TEST(ParseSize, AcceptsWxHWithinTheBounds) {
  const std::optional<Size2> s = ParseSize("32x16", 2, 8192);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->width, 32);
  EXPECT_EQ(s->height, 16);
  EXPECT_TRUE(ParseSize("2x8192", 2, 8192).has_value());
  EXPECT_TRUE(ParseSize("1x1", 1, 8192).has_value());
}

TEST(ParseSize, RefusesAnythingElse) {
  for (const char* bad : {"32x16junk", "32x16 ", " 32x16", "32 x16", "+32x16", "-3x4", "32X16", "32x", "x16", "32",
                          "", "32x16x2", "3.5x2", "0x5", "1x5", "8193x2", "99999999x2", "0x0"}) {
    EXPECT_FALSE(ParseSize(bad, 2, 8192).has_value()) << "'" << bad << "'";
  }
  EXPECT_EQ(SizeExpected(2, 4096, "32x32"), "WxH with sides from 2 to 4096, e.g. 32x32");
}

}  // namespace
}  // namespace skybake
