// fog-fit's residual map as a labelled PNG (docs/fog.md, "LUTs"): the evaluator's relative
// luminance error against the reference fog at every sample of the depth tables.
#pragma once

#include <string>

#include "fog/fog_luts.h"
#include "fog/fog_render.h"
#include "io/png_label.h"

namespace skybake::fog {

// A title; two panels, "fog" and "shadowed fog", each a grid of tiles with one row per depth table
// (labelled with its sun zenith angle and elevation) and one column per view azimuth from the sun
// (labelled); inside a tile depth samples run to the right (nearest at the left) and elevation
// samples upwards (horizon at the bottom); at the bottom a key tile with the depth and elevation
// of its samples, and the colour scale (-10 % blue .. +10 % red, white = 0; grey = excluded).
std::string ResidualPng(const FogRender& render, const FogProducts& products, const Font& font);

}  // namespace skybake::fog
