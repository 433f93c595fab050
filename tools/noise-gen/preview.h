// The PNG slice montage of a noise volume (for inspection only; the data are the KTX2/EXR).
//
// One row per channel (R, G, B, A from the top), four z slices per row (k = 0, N/4, N/2, 3N/4),
// each slice repeated 2 x 2 so that a seam would show as a line through the middle of the
// panel; panels are separated by 4 mid-grey pixels. Values map linearly from the channel's stated
// range [lo, hi] to 0..255 (grey), rows top to bottom = j ascending.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "noise/volume.h"

struct Montage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // grey, row-major
};

Montage VolumeMontage(const skybake::noise::Volume& v, const std::vector<std::pair<double, double>>& range);
