// The tabulated optical depth towards the sun (transport/sun_depth_table.h) against closed
// forms and an independent fine quadrature.
#include <gtest/gtest.h>

#include <cmath>

#include "transport/sun_depth_table.h"

using namespace skybake;

namespace {

// An exponential air of scale height 8 km (Rayleigh at 550 nm at sea level, 1.15e-5 m^-1:
// Bodhaine et al. 1999) and one of twice the density, to 100 km over the Earth (R = 6371 km),
// with 250 m levels.
AtmosphereModel ExponentialAir(double R) {
  AtmosphereModel m;
  m.bottom_radius_m = R;
  m.top_radius_m = R + 100e3;
  m.wavelength_nm = {550, 440};
  MediumComponent c;
  c.name = "air";
  c.phase = std::make_shared<IsotropicPhase>();
  for (double z = 0; z <= 100e3 + 1; z += 250.0) {
    m.altitude_m.push_back(z);
    for (double b : {1.15e-5, 2.3e-5}) {
      c.scattering.push_back(b * std::exp(-z / 8000.0));
      c.absorption.push_back(0.0);
    }
  }
  m.components.push_back(c);
  m.ground_albedo.assign(2, 0.0);
  m.sun.irradiance.assign(2, 1.0);
  m.Finalize();
  return m;
}

// Optical depth from radius r along cosine mu to the top by the midpoint rule on 200 000 steps
// (an independent quadrature; infinity when the ray meets the ground).
double FineDepth(const AtmosphereModel& m, double r, double mu, size_t w) {
  const double R = m.bottom_radius_m, top = m.top_radius_m;
  const double disc = r * r * (mu * mu - 1.0) + R * R;
  if (mu < 0.0 && disc >= 0.0) return INFINITY;
  const double L = -r * mu + std::sqrt(top * top - r * r * (1.0 - mu * mu));
  const int n = 200000;
  double tau = 0.0;
  for (int i = 0; i < n; ++i) {
    const double s = (i + 0.5) * L / n;
    const double rad = std::sqrt(r * r + 2.0 * r * mu * s + s * s);
    tau += m.Extinction(m.Locate(rad - R), w) * L / n;
  }
  return tau;
}

}  // namespace

// Vertical and slant depths from the ground: the vertical column within 0.05 % of the levels'
// piecewise-linear integral (Simpson on 1.6 km steps), the slant ones within 0.5 % of the fine
// quadrature.
TEST(SunDepthTable, VerticalAndSlantFromTheGround) {
  const AtmosphereModel m = ExponentialAir(6371e3);
  const SunDepthTable table(m);
  const double R = m.bottom_radius_m;
  for (size_t w = 0; w < 2; ++w) {
    EXPECT_NEAR(table.Depth(R, 1.0, w), m.VerticalOpticalDepth(0, 100e3, w), 5e-4 * m.VerticalOpticalDepth(0, 100e3, w));
    for (double mu : {0.7, 0.3, 0.1, 0.02}) {
      const double fine = FineDepth(m, R + 1.0, mu, w);
      EXPECT_NEAR(table.Depth(R + 1.0, mu, w), fine, 5e-3 * fine) << "mu " << mu << " wl " << w;
    }
  }
}

// Above the ground, the descending rays that pass over it (tangent heights 1-60 km, the
// twilight's sun rays) within 2 % of the fine quadrature where tau < 30, the cap beyond.
TEST(SunDepthTable, GrazingRaysAboveTheGround) {
  const AtmosphereModel m = ExponentialAir(6371e3);
  const SunDepthTable table(m);
  const double R = m.bottom_radius_m;
  for (double h : {20e3, 45e3, 80e3}) {
    const double r = R + h;
    for (double tangent : {1e3, 5e3, 12e3, 25e3, 40e3, 60e3}) {
      if (tangent >= h) continue;
      const double mu = -std::sqrt(1.0 - std::pow((R + tangent) / r, 2));
      for (size_t w = 0; w < 2; ++w) {
        const double fine = FineDepth(m, r, mu, w);
        const double got = table.Depth(r, mu, w);
        if (fine >= SunDepthTable::kMaxDepth) {
          EXPECT_NEAR(got, SunDepthTable::kMaxDepth, 0.05 * SunDepthTable::kMaxDepth) << h << " " << tangent;
        } else {
          EXPECT_NEAR(got, fine, 0.02 * fine + 0.02) << "altitude " << h << " tangent " << tangent << " wl " << w;
        }
      }
    }
  }
}

// A ray into the ground takes the grazing ray's depth (the disk can still be partly seen from
// there), that depth is the fine quadrature's within 2 %, and every depth is at most the cap.
TEST(SunDepthTable, BelowTheGrazingRayAndTheCap) {
  const AtmosphereModel m = ExponentialAir(6371e3);
  const SunDepthTable table(m);
  const double R = m.bottom_radius_m, r = R + 30e3;
  const double mu_g = -std::sqrt(1.0 - (R * R) / (r * r));
  for (size_t w = 0; w < 2; ++w) {
    EXPECT_DOUBLE_EQ(table.Depth(r, mu_g - 0.05, w), table.Depth(r, mu_g, w));
    EXPECT_LE(table.Depth(r, -1.0, w), SunDepthTable::kMaxDepth);
    // Grazing the ground: the whole line's column, sqrt(2 pi R H) sigma_0 = 6.5 at 550 nm.
    const double fine = FineDepth(m, r, mu_g + 1e-9, w);
    EXPECT_NEAR(table.Depth(r, mu_g, w), fine, 0.02 * fine);
  }
}
