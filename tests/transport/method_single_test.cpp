// The fast `single` method (transport/method_single.h) against closed forms and against the slow
// quadrature of the single-scattering integral (transport/single_scattering.h), its reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/geometric.hpp>

#include "method_scenes.h"
#include "support/log.h"
#include "transport/method_single.h"
#include "transport/single_scattering.h"
#include "transport/sky_render.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

const TestScene& Clear() {
  static const TestScene s = LoadTestScene("clear");
  return s;
}

// Relative error of Y between two spectra.
double RelY(const TestScene& s, const std::vector<double>& a, const std::vector<double>& b) {
  return s.Y(a.data()) / s.Y(b.data()) - 1.0;
}

}  // namespace

// The exact optical depth of a constant coefficient along any ray is sigma x length, and of a
// coefficient linear in altitude along the vertical is the trapezoid integral; on the real
// profile it equals the 4-point Gauss-Legendre quadrature on 100 m pieces of TransmittanceToSpace
// (sky_render.h) to 1e-6 relative, at the zenith, 60 deg, 85 deg, the horizon and from 10 km.
TEST(MethodSingle, ExactOpticalDepth) {
  {
    const AtmosphereModel m = Homogeneous(6371e3, 100e3, {1e-5, 2e-5}, {1e-6, 0.0}, std::make_shared<IsotropicPhase>(), 0.0, 11);
    LevelTables t(m);
    for (double mu : {1.0, 0.5, 0.01, -0.01}) {
      std::vector<double> tau(2, 0.0);
      ExactOpticalDepth(t, m.bottom_radius_m + 5e3, mu, 40e3, tau.data());
      EXPECT_NEAR(tau[0], 1.1e-5 * 40e3, 1e-12) << mu;
      EXPECT_NEAR(tau[1], 2e-5 * 40e3, 1e-12) << mu;
    }
  }
  const AtmosphereModel& m = Clear().model;
  LevelTables t(m);
  for (double h : {0.0, 10e3}) {
    for (double zen : {0.0, 60.0, 85.0, 90.0}) {
      std::vector<double> tau(m.wavelengths(), 0.0);
      const double r = m.bottom_radius_m + h, mu = std::cos(zen * kDeg);
      const double len = -r * mu + std::sqrt(r * r * (mu * mu - 1) + m.top_radius_m * m.top_radius_m);
      ExactOpticalDepth(t, r, mu, len, tau.data());
      for (size_t w : {0u, 8u, 20u}) {
        const double ref = -std::log(TransmittanceToSpace(m, h, zen * kDeg, w));
        EXPECT_NEAR(tau[w] / ref, 1.0, 1e-6) << "h " << h << " zenith " << zen << " wl " << w;
      }
      // The all-wavelength walk (what the LUT renders use) gives each wavelength's value bit
      // for bit, rays into the ground (0) included.
      for (double z : {zen, 180.0 - zen}) {
        std::vector<double> all;
        TransmittanceToSpace(m, h, z * kDeg, &all);
        ASSERT_EQ(all.size(), m.wavelengths());
        for (size_t w = 0; w < m.wavelengths(); ++w) EXPECT_EQ(all[w], TransmittanceToSpace(m, h, z * kDeg, w)) << z << " " << w;
      }
    }
  }
  std::vector<double> tau(m.wavelengths(), 0.0);
  ExactOpticalDepth(t, m.bottom_radius_m, 1.0, m.altitude_m.back(), tau.data());
  EXPECT_NEAR(tau[5] / m.VerticalOpticalDepth(0, m.altitude_m.back(), 5), 1.0, 1e-12);
}

// The transmittance table interpolates the exact optical depth: worst error of T = e^-tau (absolute)
// and of tau (absolute = the relative error of T, where T > 5 %) over altitudes and angles off the nodes, from daylight to
// grazing rays, per table size (the bounds are the measured values rounded up; docs/sky-methods.md).
TEST(MethodSingle, TransmittanceTableError) {
  const AtmosphereModel& m = Clear().model;
  LevelTables t(m);
  struct Case {
    int n_mu, n_r;
    double max_dt, max_rel_tau;
  };
  for (const Case c : {Case{64, 16, 1.2e-2, 6e-2}, Case{128, 32, 3.5e-3, 1.8e-2}, Case{256, 64, 6e-4, 3e-3}}) {
    TransmittanceTable table(t, c.n_mu, c.n_r);
    double worst_dt = 0.0, worst_rel = 0.0;
    std::vector<double> exact(m.wavelengths()), interp(m.wavelengths());
    for (double h : {0.0, 37.0, 450.0, 1300.0, 5100.0, 17e3, 61e3}) {
      const double r = m.bottom_radius_m + h;
      const double mu_h = table.HorizonMu(r);
      for (double f : {0.0, 0.003, 0.03, 0.11, 0.37, 0.73, 0.97}) {
        const double mu = mu_h + (1.0 - mu_h) * f * f;  // dense near the horizon
        std::fill(exact.begin(), exact.end(), 0.0);
        const double len = -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1) + m.top_radius_m * m.top_radius_m));
        ExactOpticalDepth(t, r, mu, len, exact.data());
        table.OpticalDepth(r, mu, interp.data());
        for (size_t w = 0; w < m.wavelengths(); ++w) {
          worst_dt = std::max(worst_dt, std::abs(std::exp(-interp[w]) - std::exp(-exact[w])));
          if (exact[w] < 3.0) worst_rel = std::max(worst_rel, std::abs(interp[w] - exact[w]));
        }
      }
    }
    SKYBAKE_LOG("transmittance table %dx%d: worst |dT| = %.2e, worst |dtau| (T > 5 %%) = %.2e\n", c.n_mu, c.n_r,
                worst_dt, worst_rel);
    EXPECT_LT(worst_dt, c.max_dt) << c.n_mu << "x" << c.n_r;
    EXPECT_LT(worst_rel, c.max_rel_tau) << c.n_mu << "x" << c.n_r;
  }
}

// The disk quadrature carries the solar irradiance exactly at every wavelength.
TEST(MethodSingle, SunDiskWeightsSumToIrradiance) {
  const AtmosphereModel& m = Clear().model;
  for (int rings : {0, 1, 3}) {
    SunDiskQuadrature q(m.sun, m.wavelengths(), rings, 6);
    for (size_t w = 0; w < m.wavelengths(); ++w) {
      double sum = 0.0;
      for (const auto& p : q.points) sum += p.weight[w];
      EXPECT_NEAR(sum / m.sun.irradiance[w], 1.0, 1e-12);
    }
  }
}

// Closed form: a plane-parallel-like homogeneous slab (a huge planet), point sun, black ground:
//   L = E P w0 mu_s (e^{-tau/mu_v} - e^{-tau/mu_s}) / (mu_v - mu_s)   (Chandrasekhar 1950 §9)
// seen from the bottom. The linear-exponential march is exact for a constant medium (up to the
// sun's transmittance table: tau(z) is quadratic in the table's coordinate rho = sqrt(r^2 - R^2),
// so bilinear interpolation leaves ~1e-4).
TEST(MethodSingle, HomogeneousSlabClosedForm) {
  const double R = 6371e3 * 1e4, H = 10e3;
  const double ss = 5e-5, sa = 1e-5;  // tau = 0.6
  const AtmosphereModel m = Homogeneous(R, H, {ss}, {sa}, std::make_shared<IsotropicPhase>(), 0.0);
  MarchSettings s = SingleMarchSettings(Quality::kHigh);
  s.disk_rings = 0;
  SingleScatteringModel model(m, s);
  const double tau = (ss + sa) * H, w0 = ss / (ss + sa), P = 1.0 / (4 * kPi);
  for (double theta_s : {0.0, 30.0, 60.0}) {
    for (double theta_v : {0.0, 20.0, 45.0, 70.0}) {
      const glm::dvec3 x(0, 0, R + 1e-3);
      const glm::dvec3 sun = DirectionFromAngles(theta_s * kDeg, 0);
      const glm::dvec3 v = DirectionFromAngles(theta_v * kDeg, 2.0);
      double L = 0.0;
      model.MarchRay(x, v, sun, {}, &L);
      const double mu_v = std::cos(theta_v * kDeg), mu_s = std::cos(theta_s * kDeg);
      const double exact = std::abs(mu_v - mu_s) < 1e-9
                               ? P * w0 * tau / mu_s * std::exp(-tau / mu_s)
                               : P * w0 * mu_s * (std::exp(-tau / mu_v) - std::exp(-tau / mu_s)) / (mu_v - mu_s);
      EXPECT_NEAR(L / exact, 1.0, 3e-4) << theta_s << " " << theta_v;
    }
  }
}

// The fast march against the slow quadrature (2-point Gauss-Legendre on 250 m pieces of the view
// ray, every sample's sun ray integrated to the top on 1 km pieces) on the clear sky with
// aerosols, both with a point sun (the disk is the next test): relative error of the luminance
// per quality in daylight, at sunset, in twilight (sun 4 deg below the horizon) and at -10 deg
// towards the sun (where only grazing light at 60-100 km remains), away from the sun, 2 deg
// from it and near the horizon. Measured worst (docs/sky-methods.md): low 1.9e-1 (the -10 deg
// case; 3.8e-2 otherwise), medium 4.9e-3, high 2.1e-3.
TEST(MethodSingle, MatchesSlowQuadrature) {
  const TestScene& sc = Clear();
  const AtmosphereModel& m = sc.model;
  std::vector<size_t> all(m.wavelengths());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  SingleScatteringSettings ref;
  ref.max_piece_m = 250.0;
  ref.disk_rings = 0;
  struct Case {
    double sun_zenith, view_zenith, azimuth;
  };
  const std::vector<Case> cases = {{30, 0, 0},   {30, 88, 90}, {30, 32, 0},  {90, 89, 10},
                                   {90, 60, 180}, {94, 0, 0},  {94, 85, 0},  {94, 70, 180}, {100, 80, 0}};
  std::vector<std::vector<double>> exact;
  const glm::dvec3 x(0, 0, m.bottom_radius_m + 1.0);
  for (const Case& c : cases) {
    exact.push_back(SingleScattering(m, x, DirectionFromAngles(c.view_zenith * kDeg, c.azimuth * kDeg),
                                     DirectionFromAngles(c.sun_zenith * kDeg, 0), all, ref));
  }
  SingleScatteringModel::RayOptions point;
  point.point_sun = true;
  for (const auto& [quality, bound] : std::vector<std::pair<std::string, double>>{{"low", 0.25}, {"medium", 0.01}, {"high", 0.004}}) {
    SingleScatteringModel model(m, SingleMarchSettings(ParseQuality(quality, "quality")));
    double worst = 0.0;
    for (size_t k = 0; k < cases.size(); ++k) {
      const Case& c = cases[k];
      std::vector<double> L(m.wavelengths());
      model.MarchRay(x, DirectionFromAngles(c.view_zenith * kDeg, c.azimuth * kDeg), DirectionFromAngles(c.sun_zenith * kDeg, 0),
                     point, L.data());
      const double e = RelY(sc, L, exact[k]);
      worst = std::max(worst, std::abs(e));
      EXPECT_LT(std::abs(e), bound) << quality << " sun " << c.sun_zenith << " view " << c.view_zenith << "/" << c.azimuth;
    }
    SKYBAKE_LOG("single %s vs the slow quadrature: worst |dY/Y| = %.2e\n", quality.c_str(), worst);
  }
}

// The sun disk quadrature of each quality against a fine one (12 rings x 24 points) in the same
// march: in the aureole 0.3-3 deg from the sun centre (disk radius 0.267 deg), the horizon next
// to a setting sun and in twilight. Measured worst: low (point sun) 1.7e-1 (0.2 deg above a
// setting sun's disk), medium (4 points) 2.1e-2, high (18 points) 3.7e-4.
TEST(MethodSingle, SunDiskQuadratureConverges) {
  const TestScene& sc = Clear();
  const AtmosphereModel& m = sc.model;
  const glm::dvec3 x(0, 0, m.bottom_radius_m + 1.0);
  MarchSettings fine = SingleMarchSettings(Quality::kHigh);
  fine.disk_rings = 12;
  fine.disk_sectors = 24;
  SingleScatteringModel ref(m, fine);
  struct Case {
    double sun_zenith, view_zenith;
  };
  const std::vector<Case> cases = {{30, 30.3}, {30, 30.5}, {30, 31}, {30, 33}, {90, 89.7}, {90, 89.5}, {92, 80}, {94, 60}};
  for (const auto& [quality, bound] : std::vector<std::pair<std::string, double>>{{"low", 0.25}, {"medium", 0.03}, {"high", 1e-3}}) {
    SingleScatteringModel model(m, SingleMarchSettings(ParseQuality(quality, "quality")));
    double worst = 0.0;
    for (const Case& c : cases) {
      std::vector<double> L(m.wavelengths()), R(m.wavelengths());
      const glm::dvec3 v = DirectionFromAngles(c.view_zenith * kDeg, 0), sun = DirectionFromAngles(c.sun_zenith * kDeg, 0);
      ref.MarchRay(x, v, sun, {}, R.data());
      model.MarchRay(x, v, sun, {}, L.data());
      const double e = RelY(sc, L, R);
      worst = std::max(worst, std::abs(e));
      EXPECT_LT(std::abs(e), bound) << quality << " sun " << c.sun_zenith << " view " << c.view_zenith;
    }
    SKYBAKE_LOG("single %s disk vs 288 points: worst |dY/Y| = %.2e\n", quality.c_str(), worst);
  }
}

// The ground's reflection of the direct sun, looking straight down from the ground itself (a view
// ray of length 0): L = (a/pi) mu_s E_0 T_sun with T from TransmittanceToSpace (point sun; the
// table's error at r = R: 2.4e-4 at 89 deg).
TEST(MethodSingle, GroundReflection) {
  const TestScene& sc = Clear();
  const AtmosphereModel& m = sc.model;
  MarchSettings s = SingleMarchSettings(Quality::kHigh);
  s.disk_rings = 0;
  SingleScatteringModel model(m, s);
  const glm::dvec3 x(0, 0, m.bottom_radius_m);
  for (double theta_s : {20.0, 70.0, 89.0}) {
    std::vector<double> L(m.wavelengths());
    model.MarchRay(x, glm::dvec3(0, 0, -1), DirectionFromAngles(theta_s * kDeg, 0), {}, L.data());
    for (size_t w : {0u, 10u, 20u}) {
      const double exact = m.ground_albedo[w] / kPi * std::cos(theta_s * kDeg) * m.sun.irradiance[w] *
                           TransmittanceToSpace(m, 0.0, theta_s * kDeg, w);
      EXPECT_NEAR(L[w] / exact, 1.0, 5e-4) << theta_s << " " << w;
    }
  }
}

// The Earth's shadow is geometry: with the sun 10 deg below the horizon the shadow's edge above
// the observer is at R (1/cos 10 deg - 1) = 98.5 km, so the zenith sees single scattering only
// from the last 1.5 km of a 100 km atmosphere (air density there ~5e-7 of the ground's), and
// looking down into the shadowed ground gives 0.
TEST(MethodSingle, EarthShadow) {
  const TestScene& sc = Clear();
  const AtmosphereModel& m = sc.model;
  SingleScatteringModel model(m, SingleMarchSettings(Quality::kMedium));
  const glm::dvec3 x(0, 0, m.bottom_radius_m + 1.0);
  std::vector<double> day(m.wavelengths()), night(m.wavelengths()), ground(m.wavelengths());
  model.MarchRay(x, glm::dvec3(0, 0, 1), DirectionFromAngles(60 * kDeg, 0), {}, day.data());
  model.MarchRay(x, glm::dvec3(0, 0, 1), DirectionFromAngles(100 * kDeg, 0), {}, night.data());
  model.MarchRay(x, DirectionFromAngles(120 * kDeg, 0), DirectionFromAngles(100 * kDeg, 0), {}, ground.data());
  EXPECT_LT(sc.Y(night.data()), 1e-6 * sc.Y(day.data()));
  EXPECT_EQ(sc.Y(ground.data()), 0.0);
}

// Same directions in any batch and order: identical bits (texels are independent).
TEST(MethodSingle, DeterministicPerDirection) {
  const AtmosphereModel& m = Clear().model;
  SkyMethodOptions o;
  o.quality = Quality::kMedium;
  std::unique_ptr<SkyMethod> method = MakeSkyMethod("single", m, o, {});
  std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(45, 30), Dir(89, 170), Dir(120, 0)};
  std::vector<double> a, b;
  method->Radiance(0.0, 1.2, dirs, &a);
  std::reverse(dirs.begin(), dirs.end());
  method->Radiance(0.0, 1.2, dirs, &b);
  const size_t nw = m.wavelengths();
  for (size_t d = 0; d < dirs.size(); ++d) {
    for (size_t w = 0; w < nw; ++w) EXPECT_EQ(a[d * nw + w], b[(dirs.size() - 1 - d) * nw + w]);
  }
}
