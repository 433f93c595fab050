#include "lut/r11g11b10.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "io/error.h"

namespace skybake::r11g11b10 {

// Rounding straight from the float32 bits. A positive normal float is mant * 2^(E - 150) with
// mant = 2^23 + (its 23 fraction bits) and E its biased exponent. The target code's quantum in
// the binade of target exponent e_t = max(1, E - 127 + 15) is 2^(e_t - 15 - M) (denormals share
// the quantum of e_t = 1), so the code's integer significand is q = round(mant / 2^sh) with
// sh = (e_t - 15 - M) - (E - 150), and the code is ((e_t - 1) << M) + q: for a normal target
// q in [2^M, 2^(M+1)] (a carry to 2^(M+1) lands on the next binade's mantissa 0), for a denormal
// q in [0, 2^M] (q = 2^M is the smallest normal). Monotonic in the value, so clamping the code
// clamps the value.
uint32_t PackUfloat(float value, int mantissa_bits) {
  SKYBAKE_CHECK(mantissa_bits == kMantissaBits11 || mantissa_bits == kMantissaBits10);
  const int M = mantissa_bits;
  const uint32_t max_code = MaxFiniteCode(M);
  const uint32_t bits = std::bit_cast<uint32_t>(value);
  if (bits & 0x80000000u) return 0;                     // negative, -0 (and negative NaN)
  const uint32_t E = bits >> 23;                        // biased exponent (sign is 0)
  if (E == 0xFF) return (bits & 0x7FFFFFu) ? 0 : max_code;  // NaN -> 0, +inf -> largest finite
  if (E == 0) return 0;                                 // float denormals < 2^-126: far below 2^-21
  const int e = static_cast<int>(E) - 127 + 15;         // target exponent before rounding
  if (e > 30) return max_code;                          // >= 2^16: above every code
  const int e_t = e < 1 ? 1 : e;
  const int sh = (e_t - 15 - M) - (static_cast<int>(E) - 150);  // >= 23 - M >= 17
  if (sh >= 25) return 0;                               // value < quantum / 2: rounds to 0
  const uint32_t mant = (bits & 0x7FFFFFu) | 0x800000u;
  uint32_t q = mant >> sh;
  const uint32_t rem = mant & ((1u << sh) - 1u);
  const uint32_t half = 1u << (sh - 1);
  if (rem > half || (rem == half && (q & 1u))) ++q;    // nearest, ties to even
  const uint32_t code = (static_cast<uint32_t>(e_t - 1) << M) + q;
  return code > max_code ? max_code : code;
}

float UnpackUfloat(uint32_t code, int mantissa_bits) {
  SKYBAKE_CHECK(mantissa_bits == kMantissaBits11 || mantissa_bits == kMantissaBits10);
  const int M = mantissa_bits;
  const uint32_t e = (code >> M) & 31u, m = code & ((1u << M) - 1u);
  if (e == 31) return m ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  if (e == 0) return std::ldexp(static_cast<float>(m), -14 - M);
  return std::ldexp(static_cast<float>((1u << M) + m), static_cast<int>(e) - 15 - M);
}

uint32_t Pack(float r, float g, float b) {
  return PackUfloat(r, kMantissaBits11) | (PackUfloat(g, kMantissaBits11) << 11) | (PackUfloat(b, kMantissaBits10) << 22);
}

std::array<float, 3> Unpack(uint32_t t) {
  return {UnpackUfloat(t & 0x7FFu, kMantissaBits11), UnpackUfloat((t >> 11) & 0x7FFu, kMantissaBits11),
          UnpackUfloat((t >> 22) & 0x3FFu, kMantissaBits10)};
}

std::string PackTexels(const std::vector<float>& rgb) {
  SKYBAKE_CHECK_EQ(rgb.size() % 3, 0u);
  std::string out(rgb.size() / 3 * 4, '\0');
  for (size_t t = 0; t < rgb.size() / 3; ++t) {
    const uint32_t w = Pack(rgb[3 * t], rgb[3 * t + 1], rgb[3 * t + 2]);
    for (int i = 0; i < 4; ++i) out[4 * t + i] = static_cast<char>((w >> (8 * i)) & 0xFFu);
  }
  return out;
}

std::vector<float> UnpackTexels(const std::string& bytes) {
  SKYBAKE_CHECK_EQ(bytes.size() % 4, 0u);
  std::vector<float> out;
  out.reserve(bytes.size() / 4 * 3);
  for (size_t t = 0; t < bytes.size() / 4; ++t) {
    uint32_t w = 0;
    for (int i = 0; i < 4; ++i) w |= static_cast<uint32_t>(static_cast<uint8_t>(bytes[4 * t + i])) << (8 * i);
    const std::array<float, 3> v = Unpack(w);
    out.insert(out.end(), v.begin(), v.end());
  }
  return out;
}

}  // namespace skybake::r11g11b10
