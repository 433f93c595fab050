#include "transport/rgb_color.h"

#include <cmath>

#include "spectrum/grid.h"

namespace skybake {

std::vector<std::array<double, 3>> RgbGridXyzWeights(const Cmf& cmf, const TabulatedSpectrum& solar,
                                                     const ColorConfig& config, double p, std::array<double, 3>* k_out) {
  const WavelengthGrid rgb = WavelengthGrid::Rgb();
  const Spectrum e_rgb = Resample(solar, rgb, Resampling::kBinAverage);
  const char* xyz_space = XyzColorSpace(cmf.observer());
  const ColorProcessor to709 = config.Converter(xyz_space, ocio_names::kLinearRec709);
  const ColorProcessor from709 = config.Converter(ocio_names::kLinearRec709, xyz_space);
  // The colour-matching functions in Linear Rec.709 on 1 nm steps over the observer's support.
  const int lo = static_cast<int>(std::ceil(cmf.min_nm())), hi = static_cast<int>(std::floor(cmf.max_nm()));
  std::vector<float> bars;
  for (int l = lo; l <= hi; ++l) {
    const std::array<double, 3> c = cmf.Eval(l);
    bars.insert(bars.end(), {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])});
  }
  to709.Apply(bars);
  std::array<double, 3> k{0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const double lc = rgb[static_cast<size_t>(c)], ec = e_rgb.values[static_cast<size_t>(c)];
    for (int l = lo; l <= hi; ++l) {
      if (l < solar.wavelength_nm.front() || l > solar.wavelength_nm.back()) continue;
      k[static_cast<size_t>(c)] += bars[static_cast<size_t>(l - lo) * 3 + c] * solar.Eval(l) / ec * std::pow(l / lc, p);
    }
    k[static_cast<size_t>(c)] *= 683.0;  // lm/W (SI candela; docs/color.md §4), 1 nm steps
  }
  std::vector<std::array<double, 3>> w(3);
  for (int c = 0; c < 3; ++c) {
    std::array<float, 3> e{0, 0, 0};
    e[static_cast<size_t>(c)] = 1.0f;
    const std::array<float, 3> xyz = from709.Apply(e);
    for (int j = 0; j < 3; ++j) w[static_cast<size_t>(c)][static_cast<size_t>(j)] = k[static_cast<size_t>(c)] * xyz[static_cast<size_t>(j)];
  }
  if (k_out) *k_out = k;
  return w;
}

}  // namespace skybake
