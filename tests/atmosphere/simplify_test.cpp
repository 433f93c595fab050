// The analytic-profile simplification (atmosphere/simplify.h): columns conserved, exact inputs
// recovered, and the fitted scale heights of the shipped atmospheres.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "atmosphere/simplify.h"
#include "support/log.h"

using namespace skybake;

namespace {

VerticalProfiles Grid(double dz, double top) {
  VerticalProfiles p;
  for (double z = 0; z <= top + 1e-9; z += dz) p.altitude_m.push_back(z);
  const size_t n = p.altitude_m.size();
  p.air_number_density_m3.assign(n, 0.0);
  p.air_temperature_k.assign(n, 250.0);
  p.air_pressure_pa.assign(n, 0.0);
  p.air_mass_density_kg_m3.assign(n, 0.0);
  return p;
}

}  // namespace

// An exponential air profile and a tent of ozone are reproduced exactly (they are their own fits),
// and an elevated aerosol layer (a Gaussian at 3 km, ground value << peak) falls back to the
// first-moment exponential; every column is kept (trapezoid rule on the grid).
TEST(Simplify, ExactShapesAndColumns) {
  VerticalProfiles p = Grid(100.0, 100e3);
  const size_t n = p.altitude_m.size();
  p.has_ozone = true;
  p.ozone_number_density_m3.resize(n);
  VerticalProfiles::Aerosol a;
  a.name = "elevated";
  a.shape_per_m.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double z = p.altitude_m[i];
    p.air_number_density_m3[i] = 2.5e25 * std::exp(-z / 8000.0);
    p.ozone_number_density_m3[i] = 5e18 * std::max(0.0, 1.0 - std::abs(z - 25e3) / 15e3);
    a.shape_per_m[i] = std::exp(-0.5 * std::pow((z - 3000.0) / 800.0, 2));
  }
  const double ca = TrapezoidColumn(p.altitude_m, a.shape_per_m);
  for (double& v : a.shape_per_m) v /= ca;
  p.aerosols.push_back(a);
  std::vector<ProfileFit> fits;
  const VerticalProfiles q = AnalyticProfiles(p, &fits);
  ASSERT_EQ(fits.size(), 3u);
  EXPECT_EQ(fits[0].shape, "exponential");
  EXPECT_NEAR(fits[0].scale_height_m, 8000.0, 1e-6);
  EXPECT_NEAR(fits[0].ground_value / 2.5e25, 1.0, 1e-12);
  EXPECT_EQ(fits[1].shape, "tent");
  EXPECT_NEAR(fits[1].centre_m, 25e3, 1e-6);
  EXPECT_NEAR(fits[1].half_width_m, 15e3, 5.0);  // the grid's trapezoid moments of a sampled tent
  EXPECT_EQ(fits[2].shape, "exponential (first moment)");
  EXPECT_NEAR(fits[2].scale_height_m, 3000.0, 1.0);
  for (size_t i = 0; i < n; i += 37) EXPECT_NEAR(q.air_number_density_m3[i] / p.air_number_density_m3[i], 1.0, 1e-9);
  EXPECT_NEAR(TrapezoidColumn(q.altitude_m, q.air_number_density_m3) / TrapezoidColumn(p.altitude_m, p.air_number_density_m3), 1.0, 1e-12);
  EXPECT_NEAR(TrapezoidColumn(q.altitude_m, q.ozone_number_density_m3) / TrapezoidColumn(p.altitude_m, p.ozone_number_density_m3), 1.0, 1e-12);
  EXPECT_NEAR(TrapezoidColumn(q.altitude_m, q.aerosols[0].shape_per_m), 1.0, 1e-12);
}

// The shipped clear atmosphere. Air in hydrostatic equilibrium has column p_0/(m g) and ground
// density p_0/(k T_0), so the fit's H ~ column/n_0 = k T_0/(m g_0) = 8.434 km for US Std 1976
// (T_0 288.15 K, m 28.9644 g/mol, g_0 9.80665 m/s^2), +0.2 % because g falls with altitude: within
// 8.40-8.50 km. The Shettle & Fenn 50 km-visibility aerosol (boundary layer + tropospheric
// background) fits H = 1-3 km; the AFGL ozone's mean altitude is 20-27 km. (Values printed for
// docs/sky-methods.md.)
TEST(Simplify, ClearAtmosphereFits) {
  AtmosphereSpec spec = LoadAtmosphere(SKYBAKE_SOURCE_DIR "/atmospheres/clear.yaml");
  spec.grid = GridSpec{100.0};
  const VerticalProfiles p = ComputeProfiles(spec);
  std::vector<ProfileFit> fits;
  AnalyticProfiles(p, &fits);
  for (const ProfileFit& f : fits) {
    SKYBAKE_LOG("%s: %s, H %.0f m, n0 %.4g, centre %.0f m, half-width %.0f m, column %.4g\n", f.constituent.c_str(), f.shape.c_str(),
                f.scale_height_m, f.ground_value, f.centre_m, f.half_width_m, f.column);
  }
  ASSERT_EQ(fits.size(), 3u);
  EXPECT_GT(fits[0].scale_height_m, 8400.0);
  EXPECT_LT(fits[0].scale_height_m, 8500.0);
  EXPECT_EQ(fits[2].shape, "exponential");
  EXPECT_GT(fits[2].scale_height_m, 1000.0);
  EXPECT_LT(fits[2].scale_height_m, 3000.0);
  EXPECT_GT(fits[1].centre_m, 20e3);
  EXPECT_LT(fits[1].centre_m, 27e3);
}
