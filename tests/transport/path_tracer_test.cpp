// The reference path tracer against closed forms and conservation laws (transport/path_tracer.h).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "transport/path_tracer.h"

using namespace skybake;

namespace {
constexpr double kPi = std::numbers::pi;

// A homogeneous layer of thickness H over a planet of radius R, with per-wavelength scattering
// and absorption coefficients (m^-1) and one phase model.
AtmosphereModel Homogeneous(double R, double H, std::vector<double> sigma_s, std::vector<double> sigma_a,
                            std::shared_ptr<const PhaseModel> phase, double albedo, size_t levels = 2) {
  AtmosphereModel m;
  m.bottom_radius_m = R;
  m.top_radius_m = R + H;
  const size_t nw = sigma_s.size();
  for (size_t i = 0; i < levels; ++i) m.altitude_m.push_back(H * static_cast<double>(i) / static_cast<double>(levels - 1));
  for (size_t w = 0; w < nw; ++w) m.wavelength_nm.push_back(400.0 + 100.0 * static_cast<double>(w));
  MediumComponent c;
  c.name = "test";
  c.phase = std::move(phase);
  for (size_t i = 0; i < levels; ++i) {
    for (size_t w = 0; w < nw; ++w) {
      c.scattering.push_back(sigma_s[w]);
      c.absorption.push_back(sigma_a[w]);
    }
  }
  m.components.push_back(c);
  m.ground_albedo.assign(nw, albedo);
  m.sun.irradiance.assign(nw, 1.0);
  m.sun.angular_radius_rad = 1e-4;
  m.Finalize();
  return m;
}

std::vector<std::array<double, 3>> UnitWeights(size_t n) { return std::vector<std::array<double, 3>>(n, {1.0, 1.0, 1.0}); }

// Exact single scattering of a homogeneous plane-parallel slab (optical thickness tau, albedo
// w0, phase value P at the scattering angle) seen from its bottom along mu_v, lit by a collimated
// irradiance E along mu_s at its top (Chandrasekhar 1950, §9; the integral of
// E P sigma_s exp(-sigma (H - s mu_v)/mu_s) exp(-sigma s) ds over the view ray):
//   L = E P w0 mu_s (exp(-tau/mu_v) - exp(-tau/mu_s)) / (mu_v - mu_s).
double SingleScatteringSlab(double E, double P, double w0, double tau, double mu_v, double mu_s) {
  if (std::abs(mu_v - mu_s) < 1e-9) return E * P * w0 * tau / mu_s * std::exp(-tau / mu_s);
  return E * P * w0 * mu_s * (std::exp(-tau / mu_v) - std::exp(-tau / mu_s)) / (mu_v - mu_s);
}
}  // namespace

// Single scattering: a huge planet (plane-parallel to 1e-6), strongly absorbing slab (single-
// scattering albedo 1e-3, so higher orders are ~1e-3 of the signal), black ground; the path
// tracer's mean must equal the closed form within 4 standard errors + 2e-3 relative.
TEST(PathTracer, SingleScatteringMatchesClosedForm) {
  const double R = 1e12, H = 10000.0;
  for (double tau : {0.05, 0.5}) {
    const double sigma_t = tau / H;
    const double w0 = 1e-3;
    AtmosphereModel m = Homogeneous(R, H, {w0 * sigma_t, 2 * w0 * sigma_t}, {(1 - w0) * sigma_t, (1 - 2 * w0) * sigma_t},
                                    std::make_shared<IsotropicPhase>(), 0.0);
    PathTracerSettings s;
    PathTracer pt(m, UnitWeights(2), s);
    const glm::dvec3 pos(0, 0, R + 1.0);
    for (auto [theta_s, theta_v] : {std::pair{30.0, 0.0}, std::pair{60.0, 45.0}, std::pair{20.0, 70.0}}) {
      const glm::dvec3 sun = DirectionFromAngles(theta_s * kPi / 180, 0.0);
      const glm::dvec3 view = DirectionFromAngles(theta_v * kPi / 180, 2.0);
      std::vector<double> mean, se;
      pt.SpectralRadiance(pos, view, sun, {0, 1}, 200000, 7, &mean, &se);
      for (int j = 0; j < 2; ++j) {
        const double expected = SingleScatteringSlab(1.0, 1.0 / (4 * kPi), w0 * (j + 1), tau, std::cos(theta_v * kPi / 180),
                                                     std::cos(theta_s * kPi / 180));
        EXPECT_NEAR(mean[static_cast<size_t>(j)], expected, 4 * se[static_cast<size_t>(j)] + 2e-3 * expected)
            << "tau " << tau << " sun " << theta_s << " view " << theta_v << " wl " << j;
      }
    }
  }
}

// White furnace: a conservative atmosphere (no absorption) over a white Lambertian ground under
// uniform unit radiance from space must be uniformly bright: L = 1 in every direction, at every
// wavelength, whatever the optical thickness and phase function (energy conservation).
TEST(PathTracer, WhiteFurnace) {
  const double R = 6371e3, H = 20000.0;
  AtmosphereModel m = Homogeneous(R, H, {1e-5, 5e-5, 2e-4}, {0, 0, 0},
                                  std::make_shared<RayleighPhase>(std::vector<double>{0.014, 0.014, 0.014}), 1.0, 5);
  PathTracerSettings s;
  s.illumination = Illumination::kUniform;
  s.wavelengths_per_path = 3;
  PathTracer pt(m, UnitWeights(3), s);
  const glm::dvec3 pos(0, 0, R + 500.0);
  int stream = 0;
  for (double theta_v : {0.0, 60.0, 89.0, 95.0, 150.0}) {
    std::vector<double> mean, se;
    pt.SpectralRadiance(pos, DirectionFromAngles(theta_v * kPi / 180, 1.0), glm::dvec3(0, 0, 1), {0, 1, 2}, 4000,
                        static_cast<uint64_t>(stream++), &mean, &se);
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(mean[static_cast<size_t>(j)], 1.0, 4 * se[static_cast<size_t>(j)] + 1e-9) << theta_v << " wl " << j;
    }
  }
}

// Ratio-tracking transmittance: unbiased estimate of exp(-tau/mu) on a (numerically) flat planet
// for an exponential profile, with tau computed independently (exact vertical integral of the
// piecewise-linear extinction, AtmosphereModel::VerticalOpticalDepth).
TEST(PathTracer, TransmittanceMatchesExpTauOverMu) {
  const double R = 1e12, H = 60000.0;
  AtmosphereModel m;
  m.bottom_radius_m = R;
  m.top_radius_m = R + H;
  m.wavelength_nm = {440, 550, 680};
  const double beta0[3] = {2.87e-5, 1.15e-5, 4.85e-6};  // Rayleigh sea level, Bodhaine 1999
  MediumComponent c;
  c.name = "rayleigh";
  c.phase = std::make_shared<IsotropicPhase>();
  for (double z = 0; z <= H; z += 250.0) {
    m.altitude_m.push_back(z);
    for (double b : beta0) {
      c.scattering.push_back(b * std::exp(-z / 8000.0));
      c.absorption.push_back(0.2 * b * std::exp(-z / 8000.0));
    }
  }
  m.components.push_back(c);
  m.ground_albedo.assign(3, 0.0);
  m.sun.irradiance.assign(3, 1.0);
  m.Finalize();
  PathTracer pt(m, UnitWeights(3), PathTracerSettings{});
  const size_t idx[3] = {0, 1, 2};
  for (double theta : {0.0, 45.0, 75.0, 85.0}) {
    const double mu = std::cos(theta * kPi / 180);
    const glm::dvec3 dir = DirectionFromAngles(theta * kPi / 180, 0.3);
    const int n = 20000;
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      Pcg32 rng(3, static_cast<uint64_t>(theta), static_cast<uint64_t>(i));
      double T[3];
      pt.Transmittance(glm::dvec3(0, 0, R), dir, idx, 3, rng, T);
      for (int j = 0; j < 3; ++j) {
        sum[j] += T[j];
        sum2[j] += T[j] * T[j];
      }
    }
    for (int j = 0; j < 3; ++j) {
      const double mean = sum[j] / n, se = std::sqrt((sum2[j] / n - mean * mean) / (n - 1));
      const double expected = std::exp(-m.VerticalOpticalDepth(0, H, static_cast<size_t>(j)) / mu);
      EXPECT_NEAR(mean, expected, 4 * se + 1e-6 * expected) << "theta " << theta << " wl " << j;
    }
  }
  // A ray that goes into the ground is blocked.
  Pcg32 rng(1, 1, 1);
  double T[3];
  pt.Transmittance(glm::dvec3(0, 0, R + 10.0), glm::dvec3(0, 0, -1), idx, 3, rng, T);
  EXPECT_EQ(T[0], 0.0);
}

// Honest error bars: 30 independent estimates (different seeds) of the same radiance scatter
// around a high-precision reference as their reported standard errors say: the sum of squared
// z-scores follows chi2(30), whose 99.9 % quantile is 59.7 (and 0.1 % quantile 11.6).
TEST(PathTracer, StandardErrorsAreHonest) {
  const double R = 6371e3, H = 30000.0;
  AtmosphereModel m = Homogeneous(R, H, {3e-5, 1e-5}, {2e-6, 1e-6},
                                  std::make_shared<RayleighPhase>(std::vector<double>{0.014, 0.014}), 0.3, 4);
  PathTracerSettings s;
  PathTracer pt(m, UnitWeights(2), s);
  const glm::dvec3 pos(0, 0, R + 10.0), sun = DirectionFromAngles(50 * kPi / 180, 0), view = DirectionFromAngles(70 * kPi / 180, 2.5);
  std::vector<double> ref, ref_se;
  pt.SpectralRadiance(pos, view, sun, {0}, 400000, 1000, &ref, &ref_se);
  double chi2 = 0.0;
  for (int seed = 0; seed < 30; ++seed) {
    PathTracerSettings s2 = s;
    s2.seed = 100 + static_cast<uint64_t>(seed);
    PathTracer pts(m, UnitWeights(2), s2);
    std::vector<double> mean, se;
    pts.SpectralRadiance(pos, view, sun, {0}, 2000, 5, &mean, &se);
    const double z = (mean[0] - ref[0]) / std::sqrt(se[0] * se[0] + ref_se[0] * ref_se[0]);
    chi2 += z * z;
  }
  EXPECT_LT(chi2, 59.7);
  EXPECT_GT(chi2, 11.6);
}

// Deterministic: the same stream gives the same bytes, a different seed a different estimate.
TEST(PathTracer, DeterministicStreams) {
  AtmosphereModel m = Homogeneous(6371e3, 20000.0, {2e-5}, {1e-6}, std::make_shared<IsotropicPhase>(), 0.2);
  PathTracerSettings s;
  s.target_relative_error = 0.05;
  PathTracer a(m, UnitWeights(1), s);
  const glm::dvec3 pos(0, 0, 6371e3 + 1), sun = DirectionFromAngles(0.5, 0), view = DirectionFromAngles(1.0, 0.5);
  ColorEstimate e1 = a.Radiance(pos, view, sun, 42), e2 = a.Radiance(pos, view, sun, 42);
  EXPECT_EQ(e1.xyz, e2.xyz);
  EXPECT_EQ(e1.paths, e2.paths);
  s.seed = 2;
  PathTracer b(m, UnitWeights(1), s);
  EXPECT_NE(b.Radiance(pos, view, sun, 42).xyz[1], e1.xyz[1]);
  EXPECT_LE(e1.xyz_stderr[1], 0.05 * e1.xyz[1] * 1.0000001);
}
