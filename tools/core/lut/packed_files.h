// A packed texture (lut/sky_lut.h PackedTexture) in the files that carry it besides KTX2: the
// inspection EXR image (decoded values, the inputs before packing, the clamp flags) and the DDS
// texture. Shared by lut-pack's sky, transmittance and ambient LUTs and fog-fit's fog LUTs.
#pragma once

#include <string>

#include "io/exr.h"
#include "lut/dds.h"
#include "lut/sky_lut.h"

namespace skybake::lut {

// Channels R, G, B (the decoded texels, physical units, Linear Rec.2020 chromaticities),
// input_R/G/B (before packing) and clamp_flags; `channels` is the skybake.channels text, the
// scale goes to skybake.scale, and the provenance is set.
ExrImage PackedInspectionImage(int width, int height, const PackedTexture& t, const Provenance& prov,
                               const std::string& channels);

// The texture's bytes as a DDS: a volume of t.depth slices, or 2D (depth 0).
dds::Texture PackedDds(const PackedTexture& t, bool volume);

}  // namespace skybake::lut
