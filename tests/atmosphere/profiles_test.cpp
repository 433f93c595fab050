// Vertical profiles: laws the computed profiles must obey.
#include <gtest/gtest.h>

#include <cmath>

#include "atmosphere/spec.h"
#include "atmosphere/ussa1976.h"
#include "atmosphere/vertical_profiles.h"
#include "io/interp.h"

using namespace skybake;

namespace {
AtmosphereSpec Parse(const std::string& yaml) {
  YamlDocument doc = YamlDocument::Parse(yaml, "t.yaml", SKYBAKE_SOURCE_DIR "/atmospheres");
  return ParseAtmosphere(doc, "t");
}
}  // namespace

// Hydrostatic balance dp/dz = -rho g(z) (the law USSA76 integrates), checked by central
// differences on the computed profile, g(z) = g0 (r0/(r0+z))^2 (USSA76 eq. 17).
TEST(Profiles, UssaAirIsInHydrostaticBalance) {
  for (double z : {500.0, 5000.0, 15000.0, 30000.0, 60000.0, 80000.0}) {
    const double h = 1.0;
    double dpdz = (ussa1976::AtGeometricAltitude(z + h).pressure_pa - ussa1976::AtGeometricAltitude(z - h).pressure_pa) / (2 * h);
    ussa1976::State s = ussa1976::AtGeometricAltitude(z);
    double g = ussa1976::kG0 * std::pow(ussa1976::kR0 / (ussa1976::kR0 + z), 2);
    EXPECT_NEAR(dpdz / (-s.mass_density_kg_m3 * g), 1.0, 2e-4) << z;
  }
}

// The ideal gas law p = n k T holds on every level (k = 1.380649e-23 J/K, exact SI).
TEST(Profiles, IdealGasLaw) {
  AtmosphereSpec spec = Parse("planet: {radius_km: 6371, top_km: 100}\ngrid: {altitude_step_m: 500}\nair: {profile: ussa1976}\n");
  VerticalProfiles p = ComputeProfiles(spec);
  for (size_t i = 0; i < p.altitude_m.size(); i += 10) {
    EXPECT_NEAR(p.air_pressure_pa[i] / (p.air_number_density_m3[i] * 1.380649e-23 * p.air_temperature_k[i]), 1.0, 1e-4)
        << p.altitude_m[i];
  }
}

// Exponential air is exactly n0 exp(-z/H) and isothermal with H = R* T / (M0 g0).
TEST(Profiles, ExponentialAir) {
  AtmosphereSpec spec = Parse(
      "planet: {radius_km: 6371, top_km: 60}\ngrid: {altitude_step_m: 1000}\n"
      "air: {profile: {exponential: {scale_height_km: 8}}, surface_number_density_m3: 2.5e25}\n");
  VerticalProfiles p = ComputeProfiles(spec);
  for (size_t i = 0; i < p.altitude_m.size(); ++i) {
    EXPECT_NEAR(p.air_number_density_m3[i] / (2.5e25 * std::exp(-p.altitude_m[i] / 8000.0)), 1.0, 1e-12);
  }
  EXPECT_NEAR(ussa1976::kRStar * p.air_temperature_k[0] / (ussa1976::kM0 * ussa1976::kG0), 8000.0, 1e-6);
}

// Ozone is rescaled to the requested column (trapezoid on the output grid), whatever the shape.
TEST(Profiles, OzoneColumnAndTent) {
  AtmosphereSpec spec = Parse(
      "planet: {radius_km: 6371, top_km: 60}\ngrid: {altitude_step_m: 250}\nair: {profile: ussa1976}\n"
      "ozone: {profile: {tent: {center_km: 25, half_width_km: 15}}, column_du: 300}\n");
  VerticalProfiles p = ComputeProfiles(spec);
  EXPECT_NEAR(Trapezoid(p.altitude_m, p.ozone_number_density_m3) / kDobsonUnitM2, 300.0, 1e-9);
  // Peak at 25 km: 300 DU spread over a tent of area 15 km (Bruneton 2017 demo: peak density
  // 300 * 2.687e20 / 15000 m^-3).
  size_t i25 = 100;
  ASSERT_DOUBLE_EQ(p.altitude_m[i25], 25000.0);
  EXPECT_NEAR(p.ozone_number_density_m3[i25] / (300 * kDobsonUnitM2 / 15000.0), 1.0, 1e-9);
  EXPECT_EQ(p.ozone_number_density_m3[0], 0.0);
}

// The AFGL 1986 U.S. Standard ozone table has ~345 DU before scaling (Anderson et al. 1986
// report 344 DU for the U.S. Standard model); kept absolute without column_du.
TEST(Profiles, AfglOzoneTableColumn) {
  AtmosphereSpec spec = Parse(
      "planet: {radius_km: 6371, top_km: 100}\ngrid: {altitude_step_m: 100}\nair: {profile: ussa1976}\n"
      "ozone: {profile: {table: {file: data/afgl1986_us_standard.csv, altitude_column: altitude_km, "
      "value_column: o3_number_density_cm3}}}\n");
  VerticalProfiles p = ComputeProfiles(spec);
  EXPECT_NEAR(p.ozone_column_du, 345.0, 5.0);
}

// Aerosol shapes are normalised to a unit column and keep the table's shape.
TEST(Profiles, AerosolShapeUnitColumn) {
  AtmosphereSpec spec = LoadAtmosphere(SKYBAKE_SOURCE_DIR "/atmospheres/clear.yaml");
  spec.grid = GridSpec{100.0};
  VerticalProfiles p = ComputeProfiles(spec);
  ASSERT_EQ(p.aerosols.size(), 1u);
  EXPECT_NEAR(Trapezoid(p.altitude_m, p.aerosols[0].shape_per_m), 1.0, 1e-12);
  // Shettle & Fenn 50 km visibility: 0.0662 km^-1 at the ground, 0.0415 at 1 km.
  EXPECT_NEAR(p.aerosols[0].shape_per_m[10] / p.aerosols[0].shape_per_m[0], 0.0415 / 0.0662, 1e-9);
  // Round trip through the EXR table (float32 storage: 1e-6 relative).
  VerticalProfiles q = ProfilesFromTable(ProfilesToTable(p), "mem");
  ASSERT_EQ(q.aerosols.size(), 1u);
  EXPECT_EQ(q.aerosols[0].name, "continental");
  EXPECT_NEAR(q.aerosols[0].shape_per_m[5] / p.aerosols[0].shape_per_m[5], 1.0, 1e-6);
  EXPECT_NEAR(q.ozone_column_du, 300.0, 1e-3);
}

TEST(Profiles, AltitudeGridIncludesTheTop) {
  AtmosphereSpec spec = Parse("planet: {radius_km: 6371, top_km: 1.05}\ngrid: {altitude_step_m: 100}\nair: {profile: ussa1976}\n");
  std::vector<double> z = spec.AltitudeGrid();
  ASSERT_EQ(z.size(), 12u);
  EXPECT_DOUBLE_EQ(z.back(), 1050.0);
  EXPECT_DOUBLE_EQ(z[10], 1000.0);
}
