// The OpenColorIO config of skybake, built from code (tools/ocio-config-gen writes it to
// ocio/config.ocio; docs/color.md §6). OCIO 2.1 has no built-in configs
// (they are 2.2+: OpenColorIO's 2.2 release notes), so skybake ships its own.
//
// Reference: CIE-XYZ-D65, scene-linear, absolute (Y in cd/m² for the renderer's output). It is
// CIE 1931 2° XYZ with no chromatic adaptation; "D65" names the encodings' white, not an
// adaptation (an equal-energy spectrum is at x = y = 1/3 in it, D65 light is at D65).
//
// Scene-linear spaces (MatrixTransform to the reference):
//   Linear Rec.2020         M_2020 from kRec2020Primaries (color/primaries.h), the scene_linear role
//   Linear Rec.709 (sRGB)   M_709 from kRec709Primaries
//   CIE 2006 2deg XYZ       XYZ computed with the CIE 2006 2° CMFs (the default observer):
//                           diag(X_w/X_w06, 1, Z_w/Z_w06) to the reference, where (X_w, 1, Z_w)
//                           is the encodings' D65 white from xy (0.3127, 0.3290) and
//                           (X_w06, 1, Z_w06) the XYZ of the CIE D65 spectrum under the CIE 2006
//                           CMFs (1 nm sums, 390-830 nm). So D65 light computed with CIE 2006 is
//                           exactly the display white, and Y (luminance) is unchanged. Why and
//                           what it costs: docs/color.md §6.2.
//   ACES2065-1              BuiltinTransform "UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD" (aces_interchange)
//   Raw                     data, no conversion
// Display spaces (BuiltinTransform from the display reference CIE-XYZ-D65):
//   sRGB - Display              "DISPLAY - CIE-XYZ-D65_to_sRGB"            (IEC 61966-2-1 piecewise EOTF)
//   Rec.1886 Rec.709 - Display  "DISPLAY - CIE-XYZ-D65_to_REC.1886-REC.709" (gamma 2.4)
//   Rec.2100-PQ - Display       "DISPLAY - CIE-XYZ-D65_to_REC.2100-PQ"      (SMPTE ST 2084; display-linear
//                               1.0 = 100 cd/m², as OCIO's "CURVE - LINEAR_to_ST-2084")
// View transform "Un-tone-mapped": identity from the scene to the display reference (exposure is
// applied by color/color.h before the view; tone mapping would go here).
// Displays sRGB, Rec.1886 Rec.709, Rec.2100-PQ, each with views Un-tone-mapped and Raw.
// Roles: reference, scene_linear, rendering and default = Linear Rec.2020, data = Raw, color_picking =
// sRGB - Display, cie_xyz_d65_interchange = CIE-XYZ-D65, aces_interchange = ACES2065-1.
#pragma once

#include <array>
#include <string>

#include "color/primaries.h"
#include "spectrum/cmf.h"
#include "spectrum/spectrum.h"
#include "spectrum/xyz.h"

namespace skybake {

// 3x3 row-major matrix M with XYZ = M · RGB for linear RGB with the given primaries and white,
// normalised so that RGB (1,1,1) has Y = 1 (SMPTE RP 177-1993: M = P · diag(P⁻¹ W), P the
// matrix of the primaries' XYZ with Y = 1, W the white's XYZ with Y = 1).
std::array<double, 9> RgbToXyzMatrix(const RgbPrimaries& primaries);

// XYZ with Y = 1 of a chromaticity (x, y): (x/y, 1, (1 - x - y)/y).
Xyz XyzOfChromaticity(const Xy& xy);

struct OcioConfigBuild {
  std::string text;           // the serialised config.ocio
  Xyz d65_cie2006;            // the CIE D65 spectrum under CIE 2006 2°, normalised to Y = 1
  std::array<double, 3> cie2006_to_reference;  // the diagonal of the CIE 2006 2deg XYZ matrix
};

// Builds, validates (OCIO Config::validate) and serialises the config. `cie2006` must be the CIE
// 2006 2° CMF, `d65` the CIE D65 relative spectral power distribution (cie_d65_1nm.csv).
// `provenance` is appended to the config's description (the generator and its inputs).
OcioConfigBuild BuildOcioConfig(const Cmf& cie2006, const TabulatedSpectrum& d65, const std::string& provenance);

}  // namespace skybake
