// The PNG slice montage of a noise volume (for inspection only; the data are the KTX2/EXR),
// labelled for a person (io/png_label.h RenderPanelSheet).
//
// One row per channel (R, G, B, A from the top, each titled with its channel name and recipe),
// four z slices per row (k = 0, N/4, N/2, 3N/4; each column headed with k and z in metres),
// each slice repeated 2 x 2 so that a seam would show as a line through the middle of the
// panel (x and y axes ticked in metres, rows top to bottom = j ascending), drawn 2 x 2 pixels
// per texel when N < 64. Values map linearly from the channel's stated range [lo, hi] to grey
// 0..255; a numbered grey scale right of each row shows the mapping.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "io/png_label.h"
#include "noise/volume.h"

skybake::PanelSheet VolumeMontage(const skybake::noise::Volume& v, const std::vector<std::pair<double, double>>& range,
                                  const std::vector<std::string>& title_lines, const std::vector<std::string>& channel_labels,
                                  double tile_size_m);
