// The inspection image of a packed texture (lut-pack's sky_<name>.exr and other_luts.exr,
// docs/lut-pack.md "Outputs"; fog-fit's inspection EXR, docs/fog.md): per texel R, G, B as a shader reads them divided by the
// scale (physical units, Linear Rec.2020), input_R/G/B before packing, and clamp_flags (bit OR of
// 1 = above the format's largest value, 2 = negative, 4 = denormal), with the colour attributes
// of a Linear Rec.2020 image, `skybake.channels` and `skybake.scale`. The caller adds its
// quantity and the provenance.
#pragma once

#include <string>

#include "io/exr.h"
#include "lut/sky_lut.h"

namespace skybake::lut {

// `channels_description` is the `skybake.channels` text; `height` is the rows of the image
// (a 3-D texture's slices stacked: height x depth).
ExrImage PackedInspectionImage(int width, int height, const PackedTexture& t, const std::string& channels_description);

}  // namespace skybake::lut
