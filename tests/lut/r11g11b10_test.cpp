// R11G11B10F packing (lut/r11g11b10.h): the decoder against the format's definition for every
// code, every code round-tripping, the encoder against a nearest-code reference for every float
// that can land on a finite non-zero code (exhaustive), ties to even, clamping, and the texel
// layout (R in bits 0-10, G in 11-21, B in 22-31).
//
// The definitions are the Vulkan / Khronos Data Format Specification 1.3 §10.3 ones, written out
// here as ldexp expressions (not taken from the code under test). The failure cases of GLM
// 0.9.9.8's packF2x11_1x10 (g-truc/glm #602: 1e-6 -> 4288, 3e-5 -> 128000, 1e5 -> 99328, -0.5 -> 0.5) are
// checked explicitly.
#include <gtest/gtest.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <limits>

#include "lut/r11g11b10.h"

using namespace skybake::r11g11b10;

namespace {

// The value of a finite code by the format's definition (M mantissa bits, bias 15).
double Definition(uint32_t code, int M) {
  const uint32_t e = code >> M, m = code & ((1u << M) - 1u);
  return e == 0 ? std::ldexp(static_cast<double>(m), -14 - M) : std::ldexp(static_cast<double>((1u << M) + m), static_cast<int>(e) - 15 - M);
}

}  // namespace

TEST(R11G11B10, DecoderMatchesTheDefinitionForEveryCode) {
  for (int M : {kMantissaBits11, kMantissaBits10}) {
    const uint32_t codes = 1u << (M + 5);
    for (uint32_t c = 0; c < codes; ++c) {
      const float v = UnpackUfloat(c, M);
      if ((c >> M) == 31) {
        if ((c & ((1u << M) - 1u)) == 0) EXPECT_TRUE(std::isinf(v) && v > 0) << c;
        else EXPECT_TRUE(std::isnan(v)) << c;
        continue;
      }
      ASSERT_EQ(static_cast<double>(v), Definition(c, M)) << "M=" << M << " code " << c;
    }
    EXPECT_EQ(UnpackUfloat(MaxFiniteCode(M), M), M == 6 ? kMaxFinite11 : kMaxFinite10);
    EXPECT_EQ(UnpackUfloat(1u << M, M), kMinNormal);
    EXPECT_EQ(UnpackUfloat(1u, M), std::ldexp(1.0f, -14 - M));  // smallest denormal
  }
  EXPECT_EQ(kMaxFinite11, 65024.0f);
  EXPECT_EQ(kMaxFinite10, 64512.0f);
}

TEST(R11G11B10, EveryRepresentableValueRoundTripsExactly) {
  for (int M : {kMantissaBits11, kMantissaBits10}) {
    for (uint32_t c = 0; c <= MaxFiniteCode(M); ++c) {
      ASSERT_EQ(PackUfloat(UnpackUfloat(c, M), M), c) << "M=" << M << " code " << c;
    }
  }
}

TEST(R11G11B10, EncoderPicksTheNearestCodeForEveryFloatThatMatters) {
  // Exhaustive over every positive float in [2^-22, 2^17) (the floats below 2^-22 round to 0 or
  // are the two smallest denormals, checked by the boundary tests; above 2^17 everything clamps):
  // the code must be the nearest finite code, a tie must pick the even code, and above the
  // largest finite value the largest finite code (clamping instead of IEEE overflow to infinity).
  for (int M : {kMantissaBits11, kMantissaBits10}) {
    const uint32_t max_code = MaxFiniteCode(M);
    std::vector<double> value(max_code + 1);
    for (uint32_t c = 0; c <= max_code; ++c) value[c] = Definition(c, M);
    std::atomic<uint64_t> failures{0};
    std::atomic<uint32_t> first_bad{0};
    const uint32_t lo = 0x34800000u, hi = 0x48000000u;  // 2^-22 .. 2^17
    tbb::parallel_for(tbb::blocked_range<uint32_t>(lo, hi, 1u << 16), [&](const tbb::blocked_range<uint32_t>& r) {
      uint64_t bad = 0;
      for (uint32_t bits = r.begin(); bits != r.end(); ++bits) {
        const double x = static_cast<double>(std::bit_cast<float>(bits));
        const uint32_t c = PackUfloat(std::bit_cast<float>(bits), M);
        bool ok = c <= max_code;
        if (ok && x >= value[max_code]) {
          ok = c == max_code;
        } else if (ok) {
          const double d = std::fabs(x - value[c]);
          if (c > 0) {
            const double dl = std::fabs(x - value[c - 1]);
            ok = d < dl || (d == dl && (c & 1u) == 0);
          }
          if (ok && c < max_code) {
            const double du = std::fabs(x - value[c + 1]);
            ok = d < du || (d == du && (c & 1u) == 0);
          }
        }
        if (!ok) {
          ++bad;
          first_bad.store(bits);
        }
      }
      failures += bad;
    });
    EXPECT_EQ(failures.load(), 0u) << "M=" << M << ", e.g. float bits 0x" << std::hex << first_bad.load();
  }
}

TEST(R11G11B10, TiesGoToTheEvenCodeAndBoundariesAreExact) {
  for (int M : {kMantissaBits11, kMantissaBits10}) {
    for (uint32_t c = 0; c < MaxFiniteCode(M); ++c) {
      const double lo = Definition(c, M), up = Definition(c + 1, M);
      const float mid = static_cast<float>((lo + up) / 2.0);  // exact: one more bit than the code
      ASSERT_EQ(static_cast<double>(mid), (lo + up) / 2.0);
      const uint32_t even = (c & 1u) ? c + 1 : c;
      ASSERT_EQ(PackUfloat(mid, M), even) << "M=" << M << " tie between " << c << " and " << c + 1;
      ASSERT_EQ(PackUfloat(std::nextafter(mid, 0.0f), M), c) << c;
      ASSERT_EQ(PackUfloat(std::nextafter(mid, 1e30f), M), c + 1) << c;
    }
  }
}

TEST(R11G11B10, NegativesNanAndOverflowAreClampedAsDocumented) {
  const float inf = std::numeric_limits<float>::infinity();
  for (int M : {kMantissaBits11, kMantissaBits10}) {
    const uint32_t max_code = MaxFiniteCode(M);
    EXPECT_EQ(PackUfloat(0.0f, M), 0u);
    EXPECT_EQ(PackUfloat(-0.0f, M), 0u);
    EXPECT_EQ(PackUfloat(-0.5f, M), 0u);  // GLM gives 0.5 (notes §4.4)
    EXPECT_EQ(PackUfloat(-inf, M), 0u);
    EXPECT_EQ(PackUfloat(std::numeric_limits<float>::quiet_NaN(), M), 0u);
    EXPECT_EQ(PackUfloat(-std::numeric_limits<float>::quiet_NaN(), M), 0u);
    EXPECT_EQ(PackUfloat(inf, M), max_code);
    EXPECT_EQ(PackUfloat(1e5f, M), max_code);  // GLM gives 99328 (notes §4.4)
    EXPECT_EQ(PackUfloat(3e38f, M), max_code);
    EXPECT_EQ(PackUfloat(std::numeric_limits<float>::denorm_min(), M), 0u);
    EXPECT_EQ(PackUfloat(std::numeric_limits<float>::min(), M), 0u);
  }
  // GLM's failures (notes §4.4): 1e-6 and 3e-5 are denormals of the 11-bit format.
  EXPECT_EQ(UnpackUfloat(PackUfloat(1e-6f, 6), 6), std::ldexp(1.0f, -20));            // 1 x 2^-20 = 9.54e-7
  EXPECT_NEAR(UnpackUfloat(PackUfloat(3e-5f, 6), 6), 3e-5, std::ldexp(1.0, -21));     // within half a denormal step
  EXPECT_EQ(UnpackUfloat(PackUfloat(0.18f, 6), 6), 0.1796875f);  // 92 x 2^-9, the nearest code
  EXPECT_EQ(UnpackUfloat(PackUfloat(65023.0f, 6), 6), 65024.0f);
  EXPECT_EQ(UnpackUfloat(PackUfloat(64000.0f, 5), 5), 63488.0f);  // the tie 63488 | 64512 goes to the even mantissa
  EXPECT_EQ(UnpackUfloat(PackUfloat(64001.0f, 5), 5), 64512.0f);  // B's largest is 64512
}

TEST(R11G11B10, RelativeErrorOfNormalValuesIsBoundedByHalfAnUlp) {
  // |x - decode(encode(x))| / x <= 2^-(M+1) for x in the normal range (sampled densely).
  for (int M : {kMantissaBits11, kMantissaBits10}) {
    double worst = 0.0;
    for (double x = kMinNormal; x < (M == 6 ? kMaxFinite11 : kMaxFinite10); x *= 1.0001237) {
      const float f = static_cast<float>(x);
      worst = std::max(worst, std::fabs(UnpackUfloat(PackUfloat(f, M), M) - static_cast<double>(f)) / f);
    }
    EXPECT_LE(worst, std::ldexp(1.0, -(M + 1))) << M;
    EXPECT_GT(worst, 0.9 * std::ldexp(1.0, -(M + 1))) << M;  // and the bound is reached
  }
}

TEST(R11G11B10, TexelLayoutIsRInTheLowBits) {
  // R = 1.0 (code 15 << 6 = 960), G = 2.0 (code 16 << 6 = 1024), B = 0.5 (code 14 << 5 = 448).
  const uint32_t t = Pack(1.0f, 2.0f, 0.5f);
  EXPECT_EQ(t, 960u | (1024u << 11) | (448u << 22));
  const std::array<float, 3> v = Unpack(t);
  EXPECT_EQ(v[0], 1.0f);
  EXPECT_EQ(v[1], 2.0f);
  EXPECT_EQ(v[2], 0.5f);
  const std::string bytes = PackTexels({1.0f, 2.0f, 0.5f, 0.0f, 0.0f, 65024.0f});
  ASSERT_EQ(bytes.size(), 8u);
  EXPECT_EQ(static_cast<uint8_t>(bytes[0]), t & 0xFF);  // little-endian
  EXPECT_EQ(static_cast<uint8_t>(bytes[3]), t >> 24);
  const std::vector<float> back = UnpackTexels(bytes);
  ASSERT_EQ(back.size(), 6u);
  EXPECT_EQ(back[5], 64512.0f);  // B clamps at its own largest value
}
