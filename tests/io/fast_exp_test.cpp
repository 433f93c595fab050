// ExpF (io/fast_exp.h) against the double-precision exp: relative error over the whole normal
// range, the exact points, and the ends (underflow to 0, overflow to inf, NaN).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "io/fast_exp.h"
#include "support/log.h"

using namespace skybake;

TEST(FastExp, WithinTwoUlpOfTheDoubleExp) {
  double worst = 0.0;
  // 2 million points on [-87, 88] (the normal range), including every integer multiple of 1/64.
  for (int i = 0; i <= 2000000; ++i) {
    const float x = -87.0f + 175.0f * static_cast<float>(i) / 2000000.0f;
    const double ref = std::exp(static_cast<double>(x));
    worst = std::max(worst, std::abs(static_cast<double>(ExpF(x)) / ref - 1.0));
  }
  SKYBAKE_LOG("ExpF: max relative error %.3g on [-87, 88] (float epsilon 1.19e-7)\n", worst);
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

TEST(FastLog, WithinItsStatedErrorOfTheDoubleLog) {
  // [1/2, 2], where ln x is near 0: absolute error. Elsewhere: relative error. 2 million points
  // each, logarithmically spaced over the normal range, plus every power of two and its
  // neighbours (the mantissa's split at sqrt(2) and the exponent's edges).
  double worst_abs = 0.0, worst_rel = 0.0;
  for (int i = 0; i <= 2000000; ++i) {
    const float x = 0.5f * std::exp2(2.0f * static_cast<float>(i) / 2000000.0f);
    worst_abs = std::max(worst_abs, std::abs(static_cast<double>(LogF(x)) - std::log(static_cast<double>(x))));
  }
  for (int i = 0; i <= 2000000; ++i) {
    const float x = std::exp2(-126.0f + 253.0f * static_cast<float>(i) / 2000000.0f);
    const double ref = std::log(static_cast<double>(x));
    if (std::abs(ref) < std::log(2.0)) continue;
    worst_rel = std::max(worst_rel, std::abs(static_cast<double>(LogF(x)) / ref - 1.0));
  }
  for (int e = -126; e <= 127; ++e) {
    const float x = std::ldexp(1.0f, e);
    for (float v : {x, std::nextafter(x, 0.0f), std::nextafter(x, 1e38f), x * 1.41421356f, std::nextafter(x * 1.41421356f, 1e38f)}) {
      if (!(v >= std::numeric_limits<float>::min()) || std::isinf(v)) continue;
      const double ref = std::log(static_cast<double>(v));
      const double err = std::abs(static_cast<double>(LogF(v)) - ref);
      if (std::abs(ref) < std::log(2.0)) worst_abs = std::max(worst_abs, err);
      else worst_rel = std::max(worst_rel, err / std::abs(ref));
    }
  }
  SKYBAKE_LOG("LogF: max absolute error %.3g on [1/2, 2], max relative error %.3g elsewhere\n", worst_abs, worst_rel);
  EXPECT_LT(worst_abs, 1.5e-7);
  EXPECT_LT(worst_rel, 1.5e-7);
  EXPECT_EQ(LogF(1.0f), 0.0f);
  EXPECT_FLOAT_EQ(LogF(2.0f), 0.6931472f);
  EXPECT_FLOAT_EQ(LogF(1e-30f), -69.077553f);
}

TEST(FastLog, ExpOfLogRoundTrips) {
  // The geometric blend a (b/a)^t = a ExpF(t LogF(b/a)) the orders render uses: at t = 0 and 1
  // it gives a and b back to float rounding.
  double worst = 0.0;
  for (int i = 1; i <= 100000; ++i) {
    const float r = std::exp2(-20.0f + 40.0f * static_cast<float>(i) / 100000.0f);
    worst = std::max(worst, std::abs(static_cast<double>(ExpF(LogF(r))) / r - 1.0));
  }
  SKYBAKE_LOG("ExpF(LogF(r)) / r - 1: max %.3g on [2^-20, 2^20]\n", worst);
  EXPECT_LT(worst, 8.0 * std::numeric_limits<float>::epsilon());
}
