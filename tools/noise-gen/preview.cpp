#include "preview.h"

#include <algorithm>
#include <cmath>

Montage VolumeMontage(const skybake::noise::Volume& v, const std::vector<std::pair<double, double>>& range) {
  constexpr int kSlices = 4, kGap = 4;
  const int n = v.resolution, panel = 2 * n;
  Montage m;
  m.width = kSlices * panel + (kSlices - 1) * kGap;
  m.height = v.channels * panel + (v.channels - 1) * kGap;
  m.pixels.assign(static_cast<size_t>(m.width) * m.height, 128);
  for (int c = 0; c < v.channels; ++c) {
    const double lo = range[c].first, hi = range[c].second;
    const double scale = hi > lo ? 255.0 / (hi - lo) : 0.0;
    for (int s = 0; s < kSlices; ++s) {
      const int k = s * n / kSlices;
      const int x0 = s * (panel + kGap), y0 = c * (panel + kGap);
      for (int y = 0; y < panel; ++y) {
        for (int x = 0; x < panel; ++x) {
          const double value = v.At(x % n, y % n, k, c);
          const double g = std::clamp((value - lo) * scale, 0.0, 255.0);
          m.pixels[static_cast<size_t>(y0 + y) * m.width + x0 + x] = static_cast<uint8_t>(std::floor(g + 0.5));
        }
      }
    }
  }
  return m;
}
