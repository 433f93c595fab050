// The files lut-pack writes for one set, encoded in memory (docs/lut-pack.md, "Outputs"):
//   sky_<name>.ktx2        KTX2 3D texture W x H x N, B10G11R11_UFLOAT_PACK32
//   sky_<name>_array.ktx2  KTX2 2D array, N layers, the same texels
//   sky_<name>.dds         DDS volume, DXGI_FORMAT_R11G11B10_FLOAT
//   sky_<name>.exr         inspection: the decoded texels (physical units), slices stacked
//                          vertically, with the packing error and clamp flags per texel
//   transmittance, sun, ambient .ktx2/.dds   one row per basis sky
//   other_luts.exr         inspection of those three (one part each)
//   contact_sheet.png      the basis skies x sun elevations 60, 20, 5, 0, -4 deg, decoded from the
//                          packed 3D textures, labelled (lut/contact_sheet.h)
#pragma once

#include <map>
#include <string>

#include "color/color.h"
#include "io/exr.h"
#include "io/png_label.h"
#include "lut/sky_lut.h"

namespace skybake::luttool {

// display.json: the OCIO config's sRGB display view of Linear Rec.2020 (the textures' space) as
// GLSL ES 3.00 from OCIO's GPU shader description, and the luminance row Y = k . rgb from OCIO's
// Linear Rec.2020 -> CIE-XYZ-D65 conversion, for a runtime that shows the textures as the PNG
// previews do (viewer/, docs/runtime.md).
std::string DisplayShaderJson(const ColorConfig& config);

// File name (in the output folder) -> bytes. A basis sky's own files carry `sky_provenance[name]`
// (its render alone among the inputs, so that an edit to another sky leaves them byte-identical);
// the set's files carry `provenance`. `config` and `font` draw the contact sheet.
std::map<std::string, std::string> EncodeLutSet(const lut::LutSet& set, const Provenance& provenance,
                                                const std::map<std::string, Provenance>& sky_provenance,
                                                const ColorConfig& config, const Font& font);

}  // namespace skybake::luttool
