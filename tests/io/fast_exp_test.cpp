// ExpF (io/fast_exp.h) against the double-precision exp: relative error over the whole normal
// range, the exact points, and the ends (underflow to 0, overflow to inf, NaN).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "io/fast_exp.h"

using namespace skybake;

TEST(FastExp, WithinTwoUlpOfTheDoubleExp) {
  double worst = 0.0;
  // 2 million points on [-87, 88] (the normal range), including every integer multiple of 1/64.
  for (int i = 0; i <= 2000000; ++i) {
    const float x = -87.0f + 175.0f * static_cast<float>(i) / 2000000.0f;
    const double ref = std::exp(static_cast<double>(x));
    worst = std::max(worst, std::abs(static_cast<double>(ExpF(x)) / ref - 1.0));
  }
  std::printf("ExpF: max relative error %.3g on [-87, 88] (float epsilon 1.19e-7)\n", worst);
  EXPECT_LT(worst, 2.0 * std::numeric_limits<float>::epsilon());
}

TEST(FastExp, ExactPointsAndEnds) {
  EXPECT_EQ(ExpF(0.0f), 1.0f);
  EXPECT_EQ(ExpF(-0.0f), 1.0f);
  EXPECT_FLOAT_EQ(ExpF(1.0f), 2.7182817f);
  EXPECT_FLOAT_EQ(ExpF(-1.0f), 0.36787945f);
  EXPECT_EQ(ExpF(-88.0f), 0.0f);   // below the smallest normal float: 0
  EXPECT_EQ(ExpF(-1000.0f), 0.0f);  // an optical depth of 1000
  EXPECT_GT(ExpF(-87.0f), 0.0f);
  EXPECT_TRUE(std::isinf(ExpF(89.0f)));
  EXPECT_TRUE(std::isnan(ExpF(std::numeric_limits<float>::quiet_NaN())));
}
