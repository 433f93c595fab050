#include "atmosphere/model.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <numbers>

#include "io/error.h"
#include "optics/rayleigh.h"

namespace skybake {

double IsotropicPhase::Eval(size_t, double) const { return 1.0 / (4.0 * std::numbers::pi); }

double RayleighPhase::Eval(size_t wl, double mu) const { return rayleigh::Phase(mu, gamma_[wl]); }
double RayleighPhase::SampleMu(size_t wl, double u) const { return rayleigh::SamplePhaseMu(u, gamma_[wl]); }

double HenyeyGreensteinPhase::Eval(double g, double mu) {
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * std::numbers::pi * d * std::sqrt(d));
}

// Inverse CDF of HG (e.g. pbrt-v4 SampleHenyeyGreenstein, written from the CDF):
//   mu = (1 + g^2 - ((1 - g^2) / (1 + g - 2 g u))^2) / (2 g),   g != 0.
double HenyeyGreensteinPhase::SampleMu(double g, double u) {
  if (std::abs(g) < 1e-4) return 2.0 * u - 1.0;
  const double s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u);
  return std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

double HenyeyGreensteinPhase::Eval(size_t wl, double mu) const { return Eval(g_[wl], mu); }
double HenyeyGreensteinPhase::SampleMu(size_t wl, double u) const { return SampleMu(g_[wl], u); }

double CornetteShanksPhase::Eval(double g, double mu) {
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return 3.0 * (1.0 - g * g) * (1.0 + mu * mu) / (8.0 * std::numbers::pi * (2.0 + g * g) * d * std::sqrt(d));
}

double CornetteShanksPhase::SampleMu(size_t wl, double u) const {
  const double g = g_[wl];
  // A SplitMix64 chain seeded by u's 53 bits.
  uint64_t state = static_cast<uint64_t>(u * 9007199254740992.0) ^ 0x9E3779B97F4A7C15ull;
  auto next = [&]() {
    state += 0x9E3779B97F4A7C15ull;
    uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  };
  for (int i = 0; i < 1000; ++i) {
    const double mu = HenyeyGreensteinPhase::SampleMu(g, next());
    if (next() * 2.0 <= 1.0 + mu * mu) return mu;  // accept with (1 + mu^2)/2
  }
  return HenyeyGreensteinPhase::SampleMu(g, u);
}

// ---------------------------------------------------------------------------- sun

double SunModel::SolidAngle() const { return 2.0 * std::numbers::pi * (1.0 - std::cos(angular_radius_rad)); }

double SunModel::MeanOverCentre(size_t wl) const {
  if (limb_coefficients.empty()) return 1.0;
  // Disk mean of I(mu)/I(1) = sum a_k mu^k over the projected disk: int_0^1 I 2 mu dmu
  // = sum_k 2 a_k / (k + 2) (Neckel & Labs 1994 tabulate this ratio; checked in the tests).
  double m = 0.0;
  for (int k = 0; k < 6; ++k) m += 2.0 * limb_coefficients[wl][static_cast<size_t>(k)] / (k + 2.0);
  return m;
}

double SunModel::Radiance(size_t wl, double alpha_rad) const {
  if (alpha_rad >= angular_radius_rad) return 0.0;
  // Centre radiance from the irradiance: E = L_c * Omega * mean (small-angle disk geometry,
  // relative error ~ alpha^2 ~ 2e-5 for the sun).
  const double centre = irradiance[wl] / (SolidAngle() * MeanOverCentre(wl));
  if (limb_coefficients.empty()) return centre;
  // Point on the solar disk: r = sin(alpha)/sin(alpha_sun) is the projected radius, mu the
  // cosine of the emission angle on the solar surface.
  const double r = std::sin(alpha_rad) / std::sin(angular_radius_rad);
  const double mu = std::sqrt(std::max(0.0, 1.0 - r * r));
  double ld = 0.0, p = 1.0;
  for (int k = 0; k < 6; ++k) {
    ld += limb_coefficients[wl][static_cast<size_t>(k)] * p;
    p *= mu;
  }
  return centre * ld;
}

// ---------------------------------------------------------------------------- model

void AtmosphereModel::Finalize() {
  const size_t nl = levels(), nw = wavelengths();
  SKYBAKE_CHECK_GE(nl, size_t{2});
  SKYBAKE_CHECK_GE(nw, size_t{1});
  SKYBAKE_CHECK_EQ(altitude_m.front(), 0.0);
  for (size_t i = 1; i < nl; ++i) SKYBAKE_CHECK_LT(altitude_m[i - 1], altitude_m[i]);
  SKYBAKE_CHECK(std::abs(bottom_radius_m + altitude_m.back() - top_radius_m) < 1e-6 * top_radius_m);
  SKYBAKE_CHECK_EQ(ground_albedo.size(), nw);
  SKYBAKE_CHECK_EQ(sun.irradiance.size(), nw);
  SKYBAKE_CHECK(sun.limb_coefficients.empty() || sun.limb_coefficients.size() == nw);
  // Uniform levels (profile-import's grid) are located by direct indexing.
  uniform_step_ = altitude_m[1] - altitude_m[0];
  for (size_t i = 1; i + 1 < nl; ++i) {
    if (std::abs(altitude_m[i] - static_cast<double>(i) * uniform_step_) > 1e-9 * altitude_m.back()) uniform_step_ = 0.0;
  }
  if (uniform_step_ > 0.0 && altitude_m.back() - altitude_m[nl - 2] > uniform_step_ * (1 + 1e-12)) uniform_step_ = 0.0;
  level_locator_ = IntervalLocator(altitude_m);
  extinction_.assign(nl * nw, 0.0);
  scattering_.assign(nl * nw, 0.0);
  for (const MediumComponent& c : components) {
    SKYBAKE_CHECK_EQ(c.scattering.size(), nl * nw);
    SKYBAKE_CHECK_EQ(c.absorption.size(), nl * nw);
    for (size_t k = 0; k < nl * nw; ++k) {
      SKYBAKE_CHECK(c.scattering[k] >= 0.0 && c.absorption[k] >= 0.0);
      scattering_[k] += c.scattering[k];
      extinction_[k] += c.scattering[k] + c.absorption[k];
    }
    SKYBAKE_CHECK(c.phase != nullptr || std::all_of(c.scattering.begin(), c.scattering.end(), [](double v) { return v == 0.0; }));
  }
}

double AtmosphereModel::Scattering(const Cell& c, size_t wl) const {
  const size_t nw = wavelengths();
  return scattering_[c.i * nw + wl] + (scattering_[(c.i + 1) * nw + wl] - scattering_[c.i * nw + wl]) * c.t;
}

double AtmosphereModel::ComponentScattering(size_t k, const Cell& c, size_t wl) const {
  const size_t nw = wavelengths();
  const std::vector<double>& s = components[k].scattering;
  return s[c.i * nw + wl] + (s[(c.i + 1) * nw + wl] - s[c.i * nw + wl]) * c.t;
}

double AtmosphereModel::MaxExtinction(size_t lo, size_t hi, size_t wl) const {
  const size_t nw = wavelengths();
  double m = 0.0;
  for (size_t i = lo; i <= hi; ++i) m = std::max(m, extinction_[i * nw + wl]);
  return m;
}

double AtmosphereModel::VerticalOpticalDepth(double a, double b, size_t wl) const {
  SKYBAKE_CHECK_LE(a, b);
  double tau = 0.0;
  double z = a;
  while (z < b) {
    Cell c = Locate(z);
    double z_next = std::min(b, altitude_m[c.i + 1]);
    if (z_next <= z) break;
    Cell c2 = Locate(z_next);
    if (c2.i != c.i) c2 = {c.i, 1.0};
    tau += 0.5 * (Extinction(c, wl) + Extinction(c2, wl)) * (z_next - z);
    z = z_next;
  }
  return tau;
}

}  // namespace skybake
