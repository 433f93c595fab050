// The labelled PNG previews of cumulus-map (for inspection only; the data are the KTX2/EXR),
// laid out by io/png_label.h RenderPanelSheet; values 0..1 map to grey 0..255 (UNORM8 rounding,
// the texels' own), with a numbered grey scale right of each row.
//
//   map       one row, two panels: R cloud density, G cloud type; north up, east to the right,
//             axes ticked in km from the world centre (on the map's sinh grid, so the ticks are
//             closer together at the edges);
//   coverage  one row per cloud type (layer), four panels: R height modulation, G low-frequency
//             weight, B mid-frequency weight, A ambient; map density 0..1 to the right, altitude
//             up (ticked in m).
#pragma once

#include <string>

#include "io/png_label.h"
#include "noise/coverage.h"
#include "noise/cumulus.h"

skybake::PanelSheet CumulusMapPreview(const skybake::noise::CumulusSpec& spec, const skybake::noise::CumulusMap& map,
                                      const std::string& input_name);
skybake::PanelSheet CoveragePreview(const skybake::noise::CoverageSpec& spec, const skybake::noise::CoverageTexture& t,
                                    const std::string& input_name);
