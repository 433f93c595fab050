// The parametric constituents of an atmosphere file (atmosphere/optics_spec.h) against closed
// forms: their coefficients, the vertical and slant transmittance of an exponential atmosphere,
// optically thin single scattering, and the white furnace with a parametric aerosol.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>

#include "atmosphere/model_build.h"
#include "atmosphere/tabulated_phase.h"
#include "atmosphere/vertical_profiles.h"
#include "transport/path_tracer.h"
#include "transport/sky_method.h"
#include "transport/sky_render.h"

namespace skybake {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// Bruneton 2017's demo constants (atmosphere/demo/demo.cc): kRayleigh 1.24062e-6 m^-1 at 1 um
// with lambda^-4, 8 km; Mie extinction 4.44e-6 m^-1, albedo 0.9, 1.2 km; here with an absorbing
// tent of 2e-6 m^-1 at 25 km (half width 15 km) and a 60 km top.
struct Params {
  double scale = 1.0;     // every coefficient times this
  double ssa = 0.9;
  double albedo = 0.0;
  std::string phase = "{cornette_shanks: {g: 0.8}}";
  double step_m = 10.0;
};

std::string Num(double v) { return fmt::format("{:.17g}", v); }

std::string ParametricYaml(const Params& p) {
  return "name: parametric\n"
         "planet: {radius_km: 6360, top_km: 60}\n"
         "air:\n"
         "  profile: {exponential: {scale_height_km: 8}}\n"
         "  scattering: {per_m: " + Num(1.24062e-6 * p.scale) +
         ", reference_wavelength_nm: 1000, power_law_exponent: 4}\n"
         "aerosols:\n"
         "  - name: haze\n"
         "    extinction: {per_m: " + Num(4.44e-6 * p.scale) + "}\n"
         "    single_scattering_albedo: " + Num(p.ssa) + "\n"
         "    phase: " + p.phase + "\n"
         "    profile: {exponential: {scale_height_km: 1.2}}\n"
         "absorbers:\n"
         "  - name: tent\n"
         "    absorption: {per_m: " + Num(2e-6 * p.scale) + "}\n"
         "    profile: {tent: {center_km: 25, half_width_km: 15}}\n"
         "ground: {albedo: " + Num(p.albedo) + "}\n"
         "sun: {spectrum: {constant_W_m2_nm: 1.0}, limb_darkening: none}\n";
}

AtmosphereModel Build(const Params& p, const WavelengthGrid& grid) {
  YamlDocument doc = YamlDocument::Parse(ParametricYaml(p), "parametric.yaml");
  AtmosphereSpec spec = ParseAtmosphere(doc, "parametric");
  spec.grid = GridSpec{p.step_m};
  VerticalProfiles prof = ComputeProfiles(spec);
  return BuildAtmosphereModel(spec, prof, grid, {}, ModelOptions{}, nullptr);
}

double RayleighAt(double nm) { return 1.24062e-6 * std::pow(nm / 1000.0, -4.0); }

// Extinction (m^-1) of the closed-form atmosphere at altitude z (m), wavelength nm.
double ClosedFormExtinction(double z, double nm) {
  const double tent = std::max(0.0, 1.0 - std::abs(z - 25e3) / 15e3);
  return RayleighAt(nm) * std::exp(-z / 8e3) + 4.44e-6 * std::exp(-z / 1.2e3) + 2e-6 * tent;
}

TEST(ParametricAtmosphere, CoefficientsAreTheFileValues) {
  const WavelengthGrid grid = WavelengthGrid::Uniform(360, 830, 10);
  const AtmosphereModel m = Build(Params{}, grid);
  ASSERT_EQ(m.components.size(), 3u);
  const size_t nw = grid.size();
  const size_t at_25km = static_cast<size_t>(25e3 / 10.0);
  ASSERT_DOUBLE_EQ(m.altitude_m[at_25km], 25e3);
  for (size_t w = 0; w < nw; ++w) {
    EXPECT_NEAR(m.components[0].scattering[w], RayleighAt(grid[w]), 1e-12 * RayleighAt(grid[w])) << grid[w];
    EXPECT_NEAR(m.components[1].scattering[w], 0.9 * 4.44e-6, 1e-18);
    EXPECT_NEAR(m.components[1].absorption[w], 0.1 * 4.44e-6, 1e-18);
    EXPECT_NEAR(m.components[2].absorption[at_25km * nw + w], 2e-6, 1e-18);
    EXPECT_EQ(m.components[2].absorption[w], 0.0);  // the tent is 0 below 10 km
  }
  // The Rayleigh phase without depolarisation: 3/(16 pi) (1 + mu^2).
  EXPECT_NEAR(m.components[0].phase->Eval(0, 0.5), 3.0 / (16 * kPi) * 1.25, 1e-15);
  // Cornette-Shanks g = 0.8 (Cornette & Shanks 1992 eq. 4) at mu = 1: 3 (1 - g^2) 2 / (8 pi (2 + g^2) (1 - g)^3).
  EXPECT_NEAR(m.components[1].phase->Eval(0, 1.0), 3 * 0.36 * 2 / (8 * kPi * 2.64 * 0.008), 1e-12);
}

// exp(-tau) with tau the closed-form optical depth: vertical (an exponential's column H (1 -
// e^{-top/H}), the tent's w) and slant (an independent Simpson quadrature of the closed-form
// extinction along the ray through the spherical shell, 2e5 intervals).
TEST(ParametricAtmosphere, TransmittanceMatchesTheClosedForm) {
  const WavelengthGrid grid = WavelengthGrid::List({360, 550, 820});
  const AtmosphereModel m = Build(Params{}, grid);
  const double R = 6360e3, top = 60e3;
  for (size_t w = 0; w < grid.size(); ++w) {
    const double tau_v = RayleighAt(grid[w]) * 8e3 * (1 - std::exp(-top / 8e3)) +
                         4.44e-6 * 1.2e3 * (1 - std::exp(-top / 1.2e3)) + 2e-6 * 15e3;
    EXPECT_NEAR(TransmittanceToSpace(m, 0.0, 0.0, w), std::exp(-tau_v), 1e-5 * std::exp(-tau_v)) << grid[w];
    for (double zenith_deg : {60.0, 80.0, 89.0}) {
      const double mu = std::cos(zenith_deg * kDeg);
      const double length = -R * mu + std::sqrt(R * R * mu * mu + (R + top) * (R + top) - R * R);
      const int n = 200000;
      double sum = 0.0;
      for (int i = 0; i <= n; ++i) {
        const double s = length * i / n;
        const double z = std::sqrt(R * R + s * s + 2 * R * s * mu) - R;
        sum += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * ClosedFormExtinction(z, grid[w]);
      }
      const double tau = sum * length / n / 3.0;
      EXPECT_NEAR(TransmittanceToSpace(m, 0.0, zenith_deg * kDeg, w), std::exp(-tau), 1e-5 * std::exp(-tau))
          << grid[w] << " nm, zenith " << zenith_deg;
    }
  }
}

// Optically thin single scattering (all coefficients x 1e-4, black ground): the zenith radiance
// under a sun at zenith angle theta_s is E0 sum_c P_c(cos theta_s) int omega_c k_c dz to first
// order in tau (the transmittances are 1 - O(tau) ~ 1 - 5e-5). The single method's altitude
// ladder at quality high (relative steps of 0.05) integrates an exponential to about
// 0.05^2 / 12 = 2e-4 (measured: +3.6e-4 to +4.0e-4), hence the 1e-3 tolerance; a wrong albedo,
// phase or coefficient moves the sum by 1 % or more.
TEST(ParametricAtmosphere, ThinSingleScatteringMatchesTheClosedForm) {
  Params p;
  p.scale = 1e-4;
  const WavelengthGrid grid = WavelengthGrid::List({440, 550, 680});
  const AtmosphereModel m = Build(p, grid);
  SkyMethodOptions so;
  so.quality = Quality::kHigh;
  std::unique_ptr<SkyMethod> single = MakeSkyMethod("single", m, so, nullptr);
  for (double sza : {0.0, 30.0, 60.0}) {
    std::vector<double> out;
    single->Radiance(0.0, sza * kDeg, {{0.0, 0.0, 1.0}}, &out);
    const double mu = std::cos(sza * kDeg);
    for (size_t w = 0; w < grid.size(); ++w) {
      const double rayleigh = 1e-4 * RayleighAt(grid[w]) * 8e3 * (1 - std::exp(-60e3 / 8e3)) * 3 / (16 * kPi) * (1 + mu * mu);
      const double g = 0.8;
      const double cs = 3 * (1 - g * g) * (1 + mu * mu) / (8 * kPi * (2 + g * g) * std::pow(1 + g * g - 2 * g * mu, 1.5));
      const double haze = 1e-4 * 0.9 * 4.44e-6 * 1.2e3 * (1 - std::exp(-60e3 / 1.2e3)) * cs;
      const double expected = rayleigh + haze;
      EXPECT_NEAR(out[w], expected, 1e-3 * expected) << grid[w] << " nm, sun zenith " << sza;
    }
  }
}

// White furnace: a conservative parametric atmosphere (parametric Rayleigh and an albedo-1 aerosol
// with a Cornette-Shanks phase; the absorbing tent removed) over a white ground under uniform
// unit radiance is uniformly bright, L = 1 (energy conservation).
TEST(ParametricAtmosphere, WhiteFurnace) {
  Params p;
  p.ssa = 1.0;
  p.albedo = 1.0;
  p.step_m = 100.0;
  const WavelengthGrid grid = WavelengthGrid::List({440, 550, 680});
  AtmosphereModel m = Build(p, grid);
  m.components.pop_back();  // the absorbing tent
  m.Finalize();
  PathTracerSettings s;
  s.illumination = Illumination::kUniform;
  s.wavelengths_per_path = 3;
  PathTracer pt(m, std::vector<std::array<double, 3>>(3, {1.0, 1.0, 1.0}), s);
  const glm::dvec3 pos(0, 0, 6360e3 + 10.0);
  uint64_t stream = 0;
  for (double theta_v : {0.0, 70.0, 89.5, 120.0}) {
    std::vector<double> mean, se;
    pt.SpectralRadiance(pos, DirectionFromAngles(theta_v * kDeg, 0.5), glm::dvec3(0, 0, 1), {0, 1, 2}, 4000, stream++,
                        &mean, &se);
    for (size_t j = 0; j < 3; ++j) EXPECT_NEAR(mean[j], 1.0, 4 * se[j] + 1e-9) << theta_v << " wl " << j;
  }
}

// A phase table (here Henyey-Greenstein g = 0.7 on 1801 angles, scaled by 4 pi as some codes
// store it) is normalised on load, evaluates as the closed form, and samples its own shape.
TEST(TabulatedPhase, NormalisesEvaluatesAndSamples) {
  std::vector<double> theta, value;
  for (int i = 0; i <= 1800; ++i) {
    theta.push_back(i * 0.1 * kDeg);
    value.push_back(4 * kPi * HenyeyGreensteinPhase::Eval(0.7, std::cos(theta.back())));
  }
  TabulatedPhase p(theta, value, "hg07");
  EXPECT_NEAR(p.normalisation(), 1.0 / (4 * kPi), 1e-4 / (4 * kPi));
  for (double mu : {-1.0, -0.3, 0.2, 0.9, 0.999, 1.0}) {
    EXPECT_NEAR(p.Eval(0, mu), HenyeyGreensteinPhase::Eval(0.7, mu), 2e-4 * HenyeyGreensteinPhase::Eval(0.7, mu)) << mu;
  }
  // Mean cosine of the samples = g (HG's first moment) within 4 standard errors.
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double mu = p.SampleMu(0, (i + 0.5) / n);
    sum += mu;
    sum2 += mu * mu;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, 0.7, 4 * se + 1e-4);
}

}  // namespace
}  // namespace skybake
