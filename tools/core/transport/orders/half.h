// IEEE 754 binary16 ("half") storage of float values: HalfFromFloat rounds to the nearest half,
// ties to even (as the F16C instruction vcvtps2ph with rounding mode 0 and as C's _Float16 cast),
// with overflow to infinity and gradual underflow to the half subnormals (2^-24 apart);
// FloatFromHalf is exact (every half is a float). IEEE 754-2008 section 3.6 (the binary16 format)
// and section 4.3.1 (roundTiesToEven).
#pragma once

#include <cstdint>
#include <cstring>

namespace skybake::orders {

inline uint16_t HalfFromFloat(float f) {
  uint32_t x;
  std::memcpy(&x, &f, sizeof x);
  const uint16_t sign = static_cast<uint16_t>((x >> 16) & 0x8000u);
  x &= 0x7fffffffu;
  if (x >= 0x7f800000u) return static_cast<uint16_t>(sign | 0x7c00u | (x > 0x7f800000u ? 0x0200u : 0u));  // inf, NaN (quiet)
  if (x >= 0x477ff000u) return static_cast<uint16_t>(sign | 0x7c00u);  // >= 65520: rounds to infinity
  if (x < 0x38800000u) {                                                // below 2^-14: a subnormal half or zero
    if (x <= 0x33000000u) return sign;                                  // <= 2^-25: rounds to 0 (the tie to even)
    const uint32_t e = x >> 23, m = (x & 0x7fffffu) | 0x800000u;       // value = m 2^(e - 150)
    const uint32_t shift = 126 - e;                                     // in units of 2^-24: m >> shift
    uint32_t r = m >> shift;
    const uint32_t rem = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
    if (rem > halfway || (rem == halfway && (r & 1u))) ++r;  // 0x400 when it rounds up to the least normal
    return static_cast<uint16_t>(sign | r);
  }
  uint32_t h = (x >> 13) - (112u << 10);  // exponent rebiased from 127 to 15, 10 mantissa bits
  const uint32_t rem = x & 0x1fffu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h;  // a carry into the exponent is the right result
  return static_cast<uint16_t>(sign | h);
}

inline float FloatFromHalf(uint16_t h) {
  const uint32_t sign = static_cast<uint32_t>(h & 0x8000u) << 16, e = (h >> 10) & 0x1fu, m = h & 0x3ffu;
  uint32_t x;
  if (e == 0) {
    const float v = static_cast<float>(m) * 0x1p-24f;  // subnormal: exact
    return sign ? -v : v;
  }
  if (e == 31) x = sign | 0x7f800000u | (m << 13);
  else x = sign | ((e + 112u) << 23) | (m << 13);
  float f;
  std::memcpy(&f, &x, sizeof f);
  return f;
}

}  // namespace skybake::orders
