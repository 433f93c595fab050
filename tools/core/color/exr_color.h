// EXR images that hold colours (docs/color.md §7): channels R, G, B with the standard
// `chromaticities` attribute that says what they are, plus `skybake.colorspace` = the OCIO name.
//
//   CIE-XYZ-D65            X, Y, Z in R, G, B; chromaticities red (1,0), green (0,1), blue (0,0),
//                          white (1/3, 1/3) (io/exr.h XyzChromaticities, the convention of
//                          OpenEXR's Chromaticities/XYZ.exr test image): XYZ not adapted, E is where R = G = B.
//   Linear Rec.2020        ITU-R BT.2020 primaries, white D65 (0.3127, 0.3290)
//   Linear Rec.709 (sRGB)  ITU-R BT.709 primaries, white D65 (OpenEXR's default)
// Other spaces (the CIE 2006 observer's XYZ, ACES2065-1, display spaces) are refused: convert to
// one of these first (color/color.h), so that any EXR reader can interpret the file.
#pragma once

#include <ImfChromaticities.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/exr.h"

namespace skybake {

Imf::Chromaticities Rec2020Chromaticities();
Imf::Chromaticities Rec709Chromaticities();
// The chromaticities written for a colour space, or nullopt for a space an EXR cannot describe.
std::optional<Imf::Chromaticities> ChromaticitiesOf(std::string_view colorspace);

// A width x height image with channels R, G, B (interleaved rgb, rows top to bottom), the
// chromaticities of `colorspace` and skybake.colorspace. InternalError for other spaces or a
// wrong size. Add provenance (SetProvenance) and write with WriteExr as usual.
ExrImage MakeColorImage(int width, int height, std::vector<float> rgb, std::string_view colorspace);

// The R, G, B channels of an image as interleaved RGB (a file read back lists its channels in
// EXR's alphabetical order B, G, R; this puts them back). InputError(display_name) when one is
// missing.
std::vector<float> InterleavedRgb(const ExrImage& image, const std::string& display_name);

// The OCIO colour space of an image read back: skybake.colorspace when present, else inferred
// from its chromaticities (XYZ, Rec.2020, Rec.709 within 1e-4; no attribute means Rec.709, the
// OpenEXR default). InputError(display_name) when neither identifies one of the three spaces or
// the R, G, B channels are missing.
std::string ColorSpaceOfImage(const ExrImage& image, const std::string& display_name);

}  // namespace skybake
