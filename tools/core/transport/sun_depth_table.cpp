#include "transport/sun_depth_table.h"

#include <algorithm>
#include <cmath>

#include "io/error.h"

namespace skybake {

namespace {

// Cosine of the grazing ray at radius r: the ray that touches the sphere of radius R.
double GrazingCosine(double r, double R) { return -std::sqrt(std::max(0.0, 1.0 - (R * R) / (r * r))); }

}  // namespace

SunDepthTable::SunDepthTable(const AtmosphereModel& m, int altitudes, int cosines, int steps)
    : bottom_(m.bottom_radius_m), top_(m.top_radius_m), na_(altitudes), nm_(cosines), nw_(m.wavelengths()) {
  SKYBAKE_CHECK(na_ >= 2 && nm_ >= 2 && steps >= 2 && steps % 2 == 0);
  const double H = top_ - bottom_;
  for (int i = 0; i < na_; ++i) {
    const double a = static_cast<double>(i) / (na_ - 1);
    radius_.push_back(bottom_ + H * a * a);
  }
  depth_.assign(static_cast<size_t>(na_) * static_cast<size_t>(nm_) * nw_, 0.0f);
  std::vector<double> tau(nw_), ext(nw_), prev(nw_);
  for (int i = 0; i < na_; ++i) {
    const double r = radius_[static_cast<size_t>(i)];
    const double mu_g = GrazingCosine(r, bottom_);
    for (int j = 0; j < nm_; ++j) {
      const double y = static_cast<double>(j) / (nm_ - 1);
      const double mu = std::min(1.0, mu_g + y * y * (1.0 - mu_g));
      // The ray x(s) = r e_z + s d: |x(s)|^2 = r^2 + 2 r mu s + s^2; lowest at s_low.
      const double s_low = std::max(0.0, -r * mu);
      const double s_exit = -r * mu + std::sqrt(std::max(0.0, top_ * top_ - r * r * (1.0 - mu * mu)));
      std::fill(tau.begin(), tau.end(), 0.0);
      for (const auto& [a, b] : {std::pair{0.0, s_low}, std::pair{s_low, s_exit}}) {
        if (!(b > a)) continue;
        const double h = (b - a) / steps;
        for (int q = 0; q <= steps; ++q) {
          const double s = a + q * h;
          const double rad = std::sqrt(std::max(0.0, r * r + 2.0 * r * mu * s + s * s));
          m.Extinction(m.Locate(std::max(0.0, rad - bottom_)), 0, nw_, ext.data());
          const double wq = (q == 0 || q == steps) ? h / 3.0 : (q % 2 == 1 ? 4.0 * h / 3.0 : 2.0 * h / 3.0);
          for (size_t w = 0; w < nw_; ++w) tau[w] += wq * ext[w];
        }
      }
      float* out = &depth_[(static_cast<size_t>(i) * static_cast<size_t>(nm_) + static_cast<size_t>(j)) * nw_];
      for (size_t w = 0; w < nw_; ++w) out[w] = static_cast<float>(std::min(kMaxDepth, tau[w]));
    }
  }
}

double SunDepthTable::Depth(double r, double mu, size_t w) const {
  double out;
  Depths(r, mu, &w, 1, &out);
  return out;
}

void SunDepthTable::Depths(double r, double mu, const size_t* w, int k, double* out) const {
  const double H = top_ - bottom_;
  const double a = std::sqrt(std::clamp((r - bottom_) / H, 0.0, 1.0)) * (na_ - 1);
  const int i0 = std::min(na_ - 2, static_cast<int>(a));
  const double fa = a - i0;
  const double rr = std::clamp(r, bottom_, top_);
  const double mu_g = GrazingCosine(rr, bottom_);
  const double x = std::clamp((mu - mu_g) / (1.0 - mu_g), 0.0, 1.0);
  const double b = std::sqrt(x) * (nm_ - 1);
  const int j0 = std::min(nm_ - 2, static_cast<int>(b));
  const double fb = b - j0;
  const float* row00 = &depth_[(static_cast<size_t>(i0) * static_cast<size_t>(nm_) + static_cast<size_t>(j0)) * nw_];
  const float* row01 = row00 + nw_;
  const float* row10 = row00 + static_cast<size_t>(nm_) * nw_;
  const float* row11 = row10 + nw_;
  for (int q = 0; q < k; ++q) {
    const size_t v = w[q];
    out[q] = (1 - fa) * ((1 - fb) * static_cast<double>(row00[v]) + fb * static_cast<double>(row01[v])) +
             fa * ((1 - fb) * static_cast<double>(row10[v]) + fb * static_cast<double>(row11[v]));
  }
}

}  // namespace skybake
