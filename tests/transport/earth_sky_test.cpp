// The path tracer on the real clear-sky atmosphere (US Std 1976 Rayleigh + AFGL ozone, no
// aerosol) against independent computations.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "atmosphere/model_build.h"
#include "spectrum/grid.h"
#include "transport/path_tracer.h"
#include "transport/single_scattering.h"

using namespace skybake;

namespace {
constexpr double kPi = std::numbers::pi;

const AtmosphereModel& ClearRayleigh() {
  static const AtmosphereModel model = [] {
    AtmosphereSpec spec = LoadAtmosphere(SKYBAKE_SOURCE_DIR "/atmospheres/clear.yaml");
    spec.grid = GridSpec{200.0};
    VerticalProfiles prof = ComputeProfiles(spec);
    ModelOptions opt;
    opt.aerosols = false;
    return BuildAtmosphereModel(spec, prof, WavelengthGrid::Uniform(400, 700, 20), {}, opt, nullptr);
  }();
  return model;
}

std::vector<std::array<double, 3>> Ones(size_t n) { return std::vector<std::array<double, 3>>(n, {1, 1, 1}); }
}  // namespace

// First order only (max_order = 1): the Monte-Carlo estimate (segment NEE, ratio tracking,
// random points on the sun disk) equals the deterministic quadrature of the single-scattering
// integral (Gauss-Legendre on the view ray and the sun rays, a 3x6 disk quadrature) within
// 4 standard errors + 0.5 %, in daylight, at sunset and in twilight (sun 4 deg below the
// horizon, where the Earth's shadow covers the lower atmosphere).
TEST(EarthSky, FirstOrderMatchesDeterministicSingleScattering) {
  const AtmosphereModel& m = ClearRayleigh();
  PathTracerSettings s;
  s.max_order = 1;
  PathTracer pt(m, Ones(m.wavelengths()), s);
  const glm::dvec3 obs(0, 0, m.bottom_radius_m + 1.0);
  const std::vector<size_t> wl = {1, 7, 14};  // 420, 540, 680 nm
  SingleScatteringSettings qs;
  qs.max_piece_m = 250.0;
  qs.disk_rings = 3;
  qs.disk_sectors = 6;
  struct Case {
    double sun_zenith, view_zenith, view_azimuth;
  };
  for (const Case& c : {Case{40, 0, 0}, Case{40, 75, 3.0}, Case{90, 60, 0.5}, Case{94, 0, 0}, Case{94, 80, 0}}) {
    const glm::dvec3 sun = DirectionFromAngles(c.sun_zenith * kPi / 180, 0);
    const glm::dvec3 view = DirectionFromAngles(c.view_zenith * kPi / 180, c.view_azimuth);
    std::vector<double> mean, se;
    pt.SpectralRadiance(obs, view, sun, wl, 20000, 3, &mean, &se);
    std::vector<double> exact = SingleScattering(m, obs, view, sun, wl, qs);
    for (size_t j = 0; j < wl.size(); ++j) {
      EXPECT_NEAR(mean[j], exact[j], 4 * se[j] + 5e-3 * exact[j])
          << "sun " << c.sun_zenith << " view " << c.view_zenith << " wl " << m.wavelength_nm[wl[j]];
    }
  }
}

// The two sun estimators (segment NEE and collision NEE) are different unbiased estimators of
// the same radiance (all orders): they agree within their combined error.
TEST(EarthSky, SegmentAndCollisionNeeAgree) {
  const AtmosphereModel& m = ClearRayleigh();
  const glm::dvec3 obs(0, 0, m.bottom_radius_m + 1.0);
  const std::vector<size_t> wl = {2, 10};
  for (double sun_zenith : {30.0, 88.0}) {
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith * kPi / 180, 0);
    const glm::dvec3 view = DirectionFromAngles(70 * kPi / 180, 2.0);
    std::vector<double> a, sa, b, sb;
    PathTracerSettings s1;
    PathTracer p1(m, Ones(m.wavelengths()), s1);
    p1.SpectralRadiance(obs, view, sun, wl, 20000, 5, &a, &sa);
    PathTracerSettings s2;
    s2.segment_nee = false;
    PathTracer p2(m, Ones(m.wavelengths()), s2);
    p2.SpectralRadiance(obs, view, sun, wl, 80000, 6, &b, &sb);
    for (size_t j = 0; j < wl.size(); ++j) {
      EXPECT_NEAR(a[j], b[j], 4 * std::hypot(sa[j], sb[j])) << sun_zenith << " wl " << j;
    }
  }
}

// Transmittance: the deterministic optical depth of the vertical column equals the exact
// integral of the piecewise-linear profile (AtmosphereModel::VerticalOpticalDepth), and slant
// paths approach tau/mu as the planet flattens... here checked on Earth at 60 deg, where the
// spherical slant path exceeds the plane-parallel one by < 0.2 % (Kasten & Young 1989 air mass
// at 60 deg: 1.9927 vs sec = 2).
TEST(EarthSky, OpticalDepthQuadrature) {
  const AtmosphereModel& m = ClearRayleigh();
  const glm::dvec3 obs(0, 0, m.bottom_radius_m);
  for (size_t w : {0u, 7u, 15u}) {
    bool blocked = true;
    const double tau = OpticalDepth(m, obs, glm::dvec3(0, 0, 1), INFINITY, w, &blocked);
    EXPECT_FALSE(blocked);
    EXPECT_NEAR(tau / m.VerticalOpticalDepth(0, m.altitude_m.back(), w), 1.0, 1e-6);
    const double slant = OpticalDepth(m, obs, DirectionFromAngles(kPi / 3, 0), INFINITY, w, &blocked);
    EXPECT_LT(slant / (2 * tau), 1.0);
    EXPECT_GT(slant / (2 * tau), 0.995);
  }
  bool blocked = false;
  OpticalDepth(m, glm::dvec3(0, 0, m.bottom_radius_m + 100.0), glm::dvec3(0, 0, -1), INFINITY, 0, &blocked);
  EXPECT_TRUE(blocked);
}
