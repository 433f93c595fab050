// Imath's binary16 conversion (imath_float_to_half, imath_half_to_float: Imath 3.1 half.h), which
// the binary16 scattering kernels use (transport/orders/modal_kernel.cpp, simd.cpp), tested where a
// conversion may be wrong: every half round-trips exactly, floats round to the nearest half with
// ties to even, the ends of the range (the largest half 65504, overflow at 65520, the subnormals
// 2^-24 apart, underflow at 2^-25) follow IEEE 754-2008 (section 3.6, binary16; section 4.3.1,
// roundTiesToEven), and where the machine has F16C the hardware conversion gives the same bits.
// This file is built without F16C, so it tests Imath's software conversion; the kernels' build,
// with F16C, gets the hardware's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <Imath/half.h>

#if defined(__x86_64__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace skybake::orders {
namespace {

TEST(Half, EveryHalfRoundTrips) {
  for (uint32_t h = 0; h <= 0xffffu; ++h) {
    const float f = imath_half_to_float(static_cast<uint16_t>(h));
    if (std::isnan(f)) {
      EXPECT_EQ((h >> 10) & 0x1fu, 0x1fu);
      EXPECT_NE(h & 0x3ffu, 0u);
      EXPECT_TRUE(std::isnan(imath_half_to_float(imath_float_to_half(f))));
      continue;
    }
    EXPECT_EQ(imath_float_to_half(f), h) << std::hex << h;
  }
}

TEST(Half, PublishedValues) {
  // IEEE 754-2008 binary16: 1 = 0x3c00, the largest 65504 = 0x7bff, the least normal 2^-14 =
  // 0x0400, the least subnormal 2^-24 = 0x0001, -2 = 0xc000, infinity 0x7c00.
  EXPECT_EQ(imath_float_to_half(1.0f), 0x3c00u);
  EXPECT_EQ(imath_float_to_half(-2.0f), 0xc000u);
  EXPECT_EQ(imath_float_to_half(65504.0f), 0x7bffu);
  EXPECT_EQ(imath_float_to_half(std::ldexp(1.0f, -14)), 0x0400u);
  EXPECT_EQ(imath_float_to_half(std::ldexp(1.0f, -24)), 0x0001u);
  EXPECT_EQ(imath_float_to_half(std::numeric_limits<float>::infinity()), 0x7c00u);
  EXPECT_EQ(imath_float_to_half(-0.0f), 0x8000u);
  EXPECT_EQ(imath_half_to_float(0x3555u), 0.333251953125f);  // the half nearest 1/3
  EXPECT_EQ(imath_float_to_half(1.0f / 3.0f), 0x3555u);
}

TEST(Half, RoundsToNearestWithTiesToEven) {
  const float ulp1 = std::ldexp(1.0f, -10);  // the half spacing in [1, 2)
  EXPECT_EQ(imath_float_to_half(1.0f + 0.5f * ulp1), 0x3c00u);         // tie: to the even 1
  EXPECT_EQ(imath_float_to_half(1.0f + 1.5f * ulp1), 0x3c02u);         // tie: to the even 1 + 2 ulp
  EXPECT_EQ(imath_float_to_half(std::nextafter(1.0f + 0.5f * ulp1, 2.0f)), 0x3c01u);
  EXPECT_EQ(imath_float_to_half(65519.0f), 0x7bffu);                   // below the overflow tie
  EXPECT_EQ(imath_float_to_half(65520.0f), 0x7c00u);                   // the tie rounds to infinity
  EXPECT_EQ(imath_float_to_half(std::ldexp(1.0f, -25)), 0x0000u);      // tie between 0 and 2^-24
  EXPECT_EQ(imath_float_to_half(std::ldexp(1.5f, -25)), 0x0001u);
  EXPECT_EQ(imath_float_to_half(std::ldexp(3.0f, -25)), 0x0002u);      // 1.5 subnormal units: to the even 2
  EXPECT_EQ(imath_float_to_half(std::ldexp(1.0f, -14) - std::ldexp(1.0f, -25)), 0x0400u);  // up into the normals
}

#if defined(__x86_64__)
// The first float of [from, to) (bit patterns, every 499th) whose conversion differs from the
// F16C instructions' (vcvtps2ph with round-to-nearest-even, vcvtph2ps), or `to`.
__attribute__((target("f16c"))) uint32_t FirstDifferenceFromF16c(uint32_t from, uint32_t to) {
  for (uint32_t x = from; x < to; x += 499u) {
    float f;
    std::memcpy(&f, &x, sizeof f);
    for (const float v : {f, -f}) {
      const uint16_t hw = static_cast<uint16_t>(_mm_cvtsi128_si32(_mm_cvtps_ph(_mm_set_ss(v), 0)) & 0xffff);
      if (imath_float_to_half(v) != hw || imath_half_to_float(hw) != _mm_cvtss_f32(_mm_cvtph_ps(_mm_cvtsi32_si128(hw)))) return x;
    }
  }
  return to;
}
#endif

// Against the hardware over every float exponent a half can hold, and infinity (a NaN stays a NaN,
// EveryHalfRoundTrips; its payload is not kept).
TEST(Half, SameBitsAsTheHardwareConversion) {
#if defined(__x86_64__)
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (!__get_cpuid(1, &a, &b, &c, &d) || !(c & bit_F16C)) GTEST_SKIP() << "no F16C on this machine";
  EXPECT_EQ(FirstDifferenceFromF16c(0x30000000u, 0x48000000u), 0x48000000u);
  EXPECT_EQ(FirstDifferenceFromF16c(0x7f800000u, 0x7f800001u), 0x7f800001u);
#else
  GTEST_SKIP() << "not an x86-64 build";
#endif
}

}  // namespace
}  // namespace skybake::orders
