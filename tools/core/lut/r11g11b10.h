// R11G11B10F ("B10G11R11_UFLOAT_PACK32" in Vulkan, "R11G11B10_FLOAT" in DXGI): three unsigned
// floats in one little-endian 32-bit word, the texel format of GT7's sky LUTs
// (GT7 sky talk, "Single Look-up Table Texture": "Texture format
// R11F_G11F_B10F; BC6h is not sufficient for color accuracy").
//
// Layout (Vulkan spec, "Packed Formats" / VK_FORMAT_B10G11R11_UFLOAT_PACK32; Khronos Data Format
// Specification 1.3 §10.3 "Unsigned 11-bit/10-bit floating-point numbers"; D3D11.3 functional
// spec §3.1.3.3 "11-bit and 10-bit floating-point"):
//   bits  0-10  R: unsigned 11-bit float, 5-bit exponent (bias 15), 6-bit mantissa
//   bits 11-21  G: unsigned 11-bit float, same
//   bits 22-31  B: unsigned 10-bit float, 5-bit exponent (bias 15), 5-bit mantissa
// A code with exponent e and mantissa m (M mantissa bits) is
//   e = 0:        m 2^-14 / 2^M                (denormals; 0 for m = 0)
//   0 < e < 31:   2^(e-15) (1 + m / 2^M)
//   e = 31:       +infinity (m = 0) or NaN (m != 0)       - never written here.
// Largest finite value: 2^15 (2 - 2^-M) = 65024 (11-bit), 64512 (10-bit); smallest normal 2^-14
// = 6.1e-5; smallest denormal 2^-20 = 9.5e-7 (11-bit), 2^-19 = 1.9e-6 (10-bit).
//
// Our packer (not GLM 0.9.9.8's packF2x11_1x10, which truncates and has no range checks,
// g-truc/glm #602; nor float -> half -> 11 bits, which rounds twice):
//   - rounds the float32 directly to the nearest code, ties to the even code (IEEE 754-2008
//     §4.3.1 roundTiesToEven), denormals included;
//   - negative values, -0 and NaN give 0 (the format has no sign; a negative Rec.2020 component is
//     a colour outside the Rec.2020 gamut - callers count those before packing);
//   - values above the largest finite value (including +infinity) give the largest finite value
//     (clamped, never infinity: a LUT texel must stay usable in shader arithmetic).
// Relative rounding error of an in-range normal value: at most 2^-(M+1), i.e. 0.78 % for R and G
// and 1.56 % for B.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace skybake::r11g11b10 {

inline constexpr int kMantissaBits11 = 6;  // R and G
inline constexpr int kMantissaBits10 = 5;  // B
inline constexpr float kMaxFinite11 = 65024.0f;
inline constexpr float kMaxFinite10 = 64512.0f;
inline constexpr float kMinNormal = 6.103515625e-05f;  // 2^-14

// The code (11 or 10 bits, in the low bits) of `value` with `mantissa_bits` = 6 or 5, rounded as
// above.
uint32_t PackUfloat(float value, int mantissa_bits);
// The value of a code (exact: every code is a float32). Codes with exponent 31 give +infinity or
// NaN as the format defines them.
float UnpackUfloat(uint32_t code, int mantissa_bits);
// Largest finite code: exponent 30, all mantissa bits set.
inline constexpr uint32_t MaxFiniteCode(int mantissa_bits) { return (31u << mantissa_bits) - 1u; }

// One texel: R in bits 0-10, G in 11-21, B in 22-31.
uint32_t Pack(float r, float g, float b);
std::array<float, 3> Unpack(uint32_t texel);

// Interleaved RGB floats -> little-endian texel words (rgb.size() must be a multiple of 3).
std::string PackTexels(const std::vector<float>& rgb);
// The inverse: little-endian words -> interleaved RGB floats (bytes.size() a multiple of 4).
std::vector<float> UnpackTexels(const std::string& bytes);

}  // namespace skybake::r11g11b10
