// e^x and ln x in single precision as plain arithmetic, so that a loop of them vectorises.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>

namespace skybake {

// std::exp / expf are library calls GCC does not vectorise without -ffast-math; with them the
// `orders` render spends 18 % of a LUT in exp (one per wavelength per view-ray point, the sun transmittance's
// logarithmic blend). Range reduction x = n ln2 + r, |r| <= ln2 / 2, n = round(x / ln2) by the
// 1.5 x 2^23 rounding trick, ln2 in two parts (Cody & Waite 1980, "Software Manual for the
// Elementary Functions": the upper part has 12 significant bits, so n ln2_hi is exact for
// |n| < 2^12); e^r by its Taylor polynomial to r^7 (remainder <= 0.347^8 / 8! = 5.6e-9, below
// float's epsilon 6e-8); 2^n written into the exponent bits. Measured: relative error <= 1.1e-7
// against the double exp on [-87, 88] (tests/io/fast_exp_test.cpp). Valid for x <= 88.3 and
// x >= -2800: below about -87.7 the result is 0 (no subnormals; e^-87.3 = 1.2e-38 is the smallest
// normal float), above 88.3 +inf, NaN gives NaN.
inline float ExpF(float x) {
  constexpr float kLog2e = 1.44269504088896341f;
  constexpr float kLn2Hi = 0.693145751953125f;        // ln 2 to 12 significant bits (exact in float)
  constexpr float kLn2Lo = 1.42860682030941723e-06f;  // ln 2 - kLn2Hi
  constexpr float kRound = 12582912.0f;               // 1.5 x 2^23: x + kRound - kRound rounds x to an integer
  const float n = (x * kLog2e + kRound) - kRound;
  const float r = (x - n * kLn2Hi) - n * kLn2Lo;
  float p = 1.0f / 5040.0f;
  p = p * r + 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  // The biased exponent clamped to 0 (the result is 0) ... 255 (inf). No float comparison here:
  // GCC turned a clamp of x into branches to the clamped constant, which stopped vectorisation.
  // n is first limited to [-256, 256] (a NaN to -256), so that the conversion to int is defined for
  // every x (NaN and |x| > 2^31 ln 2 included): the result is then 0, inf or NaN, as the unlimited formula gives.
  const float n_limited = !(n >= -256.0f) ? -256.0f : (n > 256.0f ? 256.0f : n);
  const int32_t e = std::min(std::max(static_cast<int32_t>(n_limited) + 127, int32_t{0}), int32_t{255});
  return p * std::bit_cast<float>(e << 23);
}

// ln x for a positive normal float x (2^-126 <= x < inf), as plain arithmetic (a loop of it
// vectorises, as ExpF's). x = m 2^e with m in [sqrt(1/2), sqrt(2)) read from the bits;
// ln m = 2 atanh(s), s = (m - 1)/(m + 1), |s| <= 0.1716, by its series to s^11 (remainder
// <= 2 x 0.1716^13 / 13 = 1.7e-11); e ln 2 in two parts (Cody & Waite, as ExpF: e ln2_hi is exact
// for |e| < 2^12). Measured: absolute error <= 1.2e-7 on [1/2, 2] and relative error <= 1.2e-7
// elsewhere on [2^-126, 2^127] against the double log (tests/io/fast_exp_test.cpp). Zero,
// negative, subnormal, inf and NaN arguments give unspecified values: the caller selects them out.
inline float LogF(float x) {
  constexpr float kLn2Hi = 0.693145751953125f;
  constexpr float kLn2Lo = 1.42860682030941723e-06f;
  const int32_t bits = std::bit_cast<int32_t>(x);
  int32_t mant = (bits & 0x007fffff) | 0x3f800000;  // m in [1, 2)
  // m >= sqrt(2) (0x3fb504f3): halve it and count one more power of two. As integers, so that
  // GCC keeps it a vector select.
  const int32_t up = mant > 0x3fb504f3 ? 1 : 0;
  mant -= up << 23;
  const float e = static_cast<float>(((bits >> 23) & 0xff) - 127 + up);
  const float m = std::bit_cast<float>(mant);
  const float s = (m - 1.0f) / (m + 1.0f);
  const float s2 = s * s;
  float p = 2.0f / 11.0f;
  p = p * s2 + 2.0f / 9.0f;
  p = p * s2 + 2.0f / 7.0f;
  p = p * s2 + 2.0f / 5.0f;
  p = p * s2 + 2.0f / 3.0f;
  p = p * s2 + 2.0f;
  return e * kLn2Hi + (s * p + e * kLn2Lo);
}

}  // namespace skybake
