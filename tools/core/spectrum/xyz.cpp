#include "spectrum/xyz.h"

#include <algorithm>
#include <cmath>

namespace skybake {

Chromaticity ToChromaticity(const Xyz& c) {
  const double sum = c.X + c.Y + c.Z;
  if (sum == 0.0) return {};
  return {c.X / sum, c.Y / sum};
}

XyzWeights::XyzWeights(const WavelengthGrid& grid, const Cmf& cmf) : grid_(grid), observer_(cmf.observer()) {
  SKYBAKE_CHECK(grid.is_spectral());
  SKYBAKE_CHECK_GE(grid.size(), size_t{1});
  const std::array<Spectrum, 3> bars = cmf.OnGrid(grid);
  std::vector<double>* w[3] = {&wx_, &wy_, &wz_};
  for (int c = 0; c < 3; ++c) {
    w[c]->resize(grid.size());
    for (size_t i = 0; i < grid.size(); ++i) {
      (*w[c])[i] = kMaxLuminousEfficacyLmPerW * bars[c].values[i] * grid.bin_width_nm(i);
    }
  }
}

namespace {
template <typename T>
Xyz Dot(const std::vector<double>& wx, const std::vector<double>& wy, const std::vector<double>& wz,
        std::span<const T> v) {
  SKYBAKE_CHECK_EQ(v.size(), wx.size());
  // Fixed order (i ascending): the same bits on every run and thread.
  Xyz out;
  for (size_t i = 0; i < v.size(); ++i) {
    const double l = static_cast<double>(v[i]);
    out.X += wx[i] * l;
    out.Y += wy[i] * l;
    out.Z += wz[i] * l;
  }
  return out;
}
}  // namespace

Xyz XyzWeights::Integrate(std::span<const double> values) const { return Dot(wx_, wy_, wz_, values); }
Xyz XyzWeights::Integrate(std::span<const float> values) const { return Dot(wx_, wy_, wz_, values); }

Xyz SpectrumToXyz(const XyzWeights& weights, const Spectrum& spectrum) {
  SKYBAKE_CHECK(spectrum.grid == weights.grid());
  return weights.Integrate(std::span<const double>(spectrum.values));
}

HeroWavelengths SampleHeroWavelengths(const XyzWeights& weights, double u, int count) {
  SKYBAKE_CHECK_GE(count, 1);
  SKYBAKE_CHECK_LE(count, kMaxHeroWavelengths);
  const size_t n = weights.size();
  const size_t k_count = static_cast<size_t>(count);
  // u in [0, 1): a u of exactly 1 (or NaN) would not be uniform; clamp to the largest double < 1.
  if (!(u >= 0.0)) u = 0.0;
  if (u >= 1.0) u = std::nextafter(1.0, 0.0);
  // i_k = floor(u N + k N/K) mod N, evaluated as i_0 + q_k + carry with integers where possible so
  // that the spacing is exact: u N = i_0 + r (0 <= r < 1), k N / K = q_k + rem_k / K.
  const double un = u * static_cast<double>(n);
  const size_t i0 = std::min(n - 1, static_cast<size_t>(un));
  const double r = std::clamp(un - static_cast<double>(i0), 0.0, 1.0);
  const double scale = static_cast<double>(n) / static_cast<double>(count);  // N/K, the weight factor
  HeroWavelengths h;
  h.count = count;
  for (size_t k = 0; k < k_count; ++k) {
    const size_t q = (k * n) / k_count;
    const size_t rem = (k * n) % k_count;
    const size_t carry = r + static_cast<double>(rem) / static_cast<double>(k_count) >= 1.0 ? 1 : 0;
    const size_t i = (i0 + q + carry) % n;
    h.index[k] = static_cast<int>(i);
    h.wavelength_nm[k] = weights.grid()[i];
    h.weight[k] = Xyz{scale * weights.wx()[i], scale * weights.wy()[i], scale * weights.wz()[i]};
  }
  return h;
}

}  // namespace skybake
