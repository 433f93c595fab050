// Chromaticities of the RGB encodings in ocio/config.ocio (CIE 1931 2° xy; docs/color.md §6).
//
//   ITU-R BT.2020-2 (10/2015), "System colorimetry": R (0.708, 0.292), G (0.170, 0.797),
//     B (0.131, 0.046), reference white D65 (0.3127, 0.3290).
//   ITU-R BT.709-6 (06/2015), Part 2 §1 "Opto-electronic conversion" (= IEC 61966-2-1 sRGB):
//     R (0.640, 0.330), G (0.300, 0.600), B (0.150, 0.060), white D65 (0.3127, 0.3290).
//   D65 (0.3127, 0.3290) is CIE 15:2004's (0.31272, 0.32903) rounded to 4 decimals by both
//     recommendations; the encodings' white is this rounded value.
// The same numbers feed the config generator (the RGB <-> XYZ matrices) and the EXR
// `chromaticities` attribute (color/exr_color.h), so the two cannot disagree.
#pragma once

namespace skybake {

struct Xy {
  double x, y;
};

struct RgbPrimaries {
  Xy red, green, blue, white;
};

inline constexpr Xy kD65WhiteXy{0.3127, 0.3290};
inline constexpr RgbPrimaries kRec2020Primaries{{0.708, 0.292}, {0.170, 0.797}, {0.131, 0.046}, kD65WhiteXy};
inline constexpr RgbPrimaries kRec709Primaries{{0.640, 0.330}, {0.300, 0.600}, {0.150, 0.060}, kD65WhiteXy};

}  // namespace skybake
