#include "lut/dome_view.h"

#include <cmath>
#include <numbers>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace skybake::lut {

std::array<double, 3> DomeDirection(int x, int y, int width, int height) {
  constexpr double kPi = std::numbers::pi;
  const double phi = 2.0 * kPi * (x + 0.5) / width - kPi;
  const double theta = 0.5 * kPi * (y + 0.5) / height;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

std::vector<float> DecodeDome(const std::vector<std::pair<const SkyLutDecoder*, double>>& weighted, double sun_zenith_rad,
                              int width, int height) {
  std::vector<float> out(static_cast<size_t>(width) * height * 3);
  // Every pixel is independent: the same floats at any thread count.
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const std::array<double, 3> l = BlendRadiance(weighted, DomeDirection(x, y, width, height), sun_zenith_rad);
        for (int c = 0; c < 3; ++c) out[(static_cast<size_t>(y) * width + x) * 3 + c] = static_cast<float>(l[c]);
      }
    }
  });
  return out;
}

}  // namespace skybake::lut
