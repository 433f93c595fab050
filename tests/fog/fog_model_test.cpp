// GT7's depth model (fog/fog_model.h; GT7 sky talk, "Global Fog
// Approximation"): Fog = LUT(dir) (1 - exp(-a theta^p x)) / (1 - exp(-a theta^p)). Laws checked:
// the closed-form limits (x -> 1 gives the LUT value, x -> 0 gives 0, a -> 0 gives x), the
// derivative used by the fit against finite differences, the model being exact for a homogeneous
// low atmosphere with the path angle (the reason it is skybake's default), and the geometry and
// attenuation-coordinate round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "fog/fog_model.h"
#include "io/error.h"
#include "support/log.h"

using namespace skybake;
using namespace skybake::fog;

namespace {
constexpr double kPi = std::numbers::pi;
// Earth (6371 km, the GT7 sky talk's geometry as in docs/lut-pack.md), observer on
// the ground, cut at 3.5 km (docs/fog.md, "The cut").
FogGeometry Earth() { return FogGeometry(6371e3, 0.0, 3500.0); }
}  // namespace

// x -> 1: F -> 1, so Fog -> LUT(dir) (the LUT holds the whole low-atmosphere segment); x = 0: 0;
// for every exponent from the optically thin (1e-12) to the clamp (1e6).
TEST(FogModel, DepthFactorEndpoints) {
  for (double k : {0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 7.0, 50.0, 700.0, 1e5, 1e6, 1e9}) {
    EXPECT_EQ(DepthFactor(1.0, k), 1.0) << k;
    EXPECT_EQ(DepthFactor(0.0, k), 0.0) << k;
    EXPECT_NEAR(DepthFactor(1.0 - 1e-12, k), 1.0, 1e-9 * std::max(1.0, std::min(k, 1e3))) << k;
    // x -> 0: F ~ x k / (1 - e^-k) -> 0 (the slope at 0, finite for finite k).
    const double slope = k > 0 ? k / -std::expm1(-k) : 1.0;
    if (k < 1e5) {
      EXPECT_NEAR(DepthFactor(1e-12, k) / 1e-12, slope, 1e-6 * slope) << k;
    }
    // Monotone and in [0, 1].
    double prev = 0.0;
    for (int i = 1; i <= 100; ++i) {
      const double f = DepthFactor(i / 100.0, k);
      EXPECT_GE(f, prev) << k;
      EXPECT_LE(f, 1.0) << k;
      prev = f;
    }
  }
  // Outside [0, 1]: clamped, never NaN.
  EXPECT_EQ(DepthFactor(-1.0, 3.0), 0.0);
  EXPECT_EQ(DepthFactor(2.0, 3.0), 1.0);
  EXPECT_EQ(DepthFactor(std::nan(""), 3.0), 0.0);
  EXPECT_TRUE(std::isfinite(DepthFactor(0.5, std::nan(""))));
}

// a -> 0 (k -> 0): F -> x, the optically thin segment whose fog grows linearly with depth. The
// series x (1 + k (1 - x)/2) and the direct form meet at k = 1e-8 without a step (< 1e-15).
TEST(FogModel, ThinLimitIsLinear) {
  for (double x : {1e-6, 0.01, 0.3, 0.5, 0.9, 0.999}) {
    EXPECT_NEAR(DepthFactor(x, 1e-14), x, 1e-13) << x;
    EXPECT_NEAR(DepthFactor(x, DepthExponent(1e-15, 0.7, 0.5)), x, 1e-13) << x;
    // Second order: F = x + k x (1 - x)/2 + O(k^2), checked at k = 1e-4 (error ~k^2 = 1e-8).
    const double k = 1e-4;
    EXPECT_NEAR(DepthFactor(x, k), x + 0.5 * k * x * (1 - x), 1e-8) << x;
    EXPECT_NEAR(DepthFactor(x, 1e-8 * (1 - 1e-12)), DepthFactor(x, 1e-8 * (1 + 1e-12)), 1e-15) << x;
  }
}

// Dense limit: k -> infinity gives the step 1 for x > 0 (all the fog right in front of the
// camera); the closed form 1 - e^{-kx} there.
TEST(FogModel, DenseLimitIsAStep) {
  for (double x : {1e-3, 0.1, 0.5}) {
    EXPECT_NEAR(DepthFactor(x, 1e4), 1.0, 1e-4) << x;  // 1 - e^{-10} = 1 - 4.5e-5 at x = 1e-3
    EXPECT_NEAR(DepthFactor(x, 50.0), -std::expm1(-50.0 * x) / -std::expm1(-50.0), 1e-15) << x;
  }
  // The exponent is clamped to [0, 1e6] and the angle to [1e-6, 1]: no overflow for p < 0 at the
  // horizon, no NaN for a bad angle.
  EXPECT_EQ(DepthExponent(1.0, -6.0, 0.0), kMaxExponent);
  EXPECT_NEAR(DepthExponent(2.0, -1.0, 1e-3), 2000.0, 1e-9);
  EXPECT_DOUBLE_EQ(DepthExponent(2.0, 1.0, std::nan("")), 2.0 * kThetaFloor);
  EXPECT_EQ(DepthExponent(-1.0, 1.0, 0.5), 0.0);
}

// dF/dk (the fit's Jacobian) against finite differences (second order; one-sided near k = 0),
// across the series switch at k = 1e-4 and into the saturated range. The series
// x [(1 - x)/2 + k (1/6 - x/2 + x^2/3)] drops O(k^2) terms: ~1e-8 absolute at k = 1e-4. Measured
// agreement: 1.5e-7 relative at worst (printed); bound 2e-6 relative.
TEST(FogModel, DerivativeMatchesFiniteDifferences) {
  double worst = 0.0;
  for (double k : {1e-7, 5e-5, 1e-4 * (1 - 1e-9), 1e-4 * (1 + 1e-9), 2e-4, 0.05, 0.9, 3.0, 20.0, 200.0}) {
    for (double x : {0.001, 0.05, 0.3, 0.7, 0.99}) {
      const double h = 1e-5 * std::max(k, 1.0);
      const double fd = k > h ? (DepthFactor(x, k + h) - DepthFactor(x, k - h)) / (2 * h)
                              : (-3 * DepthFactor(x, k) + 4 * DepthFactor(x, k + h) - DepthFactor(x, k + 2 * h)) / (2 * h);
      const double an = DepthFactorDk(x, k);
      EXPECT_NEAR(an, fd, 2e-6 * std::max(std::fabs(fd), 1e-6)) << "k " << k << " x " << x;
      worst = std::max(worst, std::fabs(an - fd) / std::max(std::fabs(fd), 1e-6));
    }
  }
  SKYBAKE_LOG("dF/dk vs finite differences: worst relative difference %.2g\n", worst);
  EXPECT_EQ(DepthFactorDk(0.0, 1.0), 0.0);
  EXPECT_EQ(DepthFactorDk(1.0, 1.0), 0.0);
}

// The boundary distance: D(1) = c - h straight up, D(0) = sqrt(r_c^2 - r^2) along the horizon
// (211.2 km for c = 3.5 km), D(mu < 0) = D(0); theta_path = (c - h)/D in [0.0166, 1].
TEST(FogModel, Geometry) {
  const FogGeometry g = Earth();
  const double r = 6371e3, rc = r + 3500.0;
  EXPECT_NEAR(g.BoundaryDistanceM(1.0), 3500.0, 1e-9);
  EXPECT_NEAR(g.BoundaryDistanceM(0.0), std::sqrt(rc * rc - r * r), 1e-6);
  EXPECT_NEAR(g.BoundaryDistanceM(0.0), 211209.0, 1.0);  // sqrt(6374.5^2 - 6371^2) km = 211.209 km
  EXPECT_EQ(g.BoundaryDistanceM(-0.3), g.BoundaryDistanceM(0.0));
  // The far root of |r + t mu| = r_c by the quadratic formula, away from cancellation (mu = 0.5).
  const double mu = 0.5, t = -r * mu + std::sqrt(r * r * mu * mu + rc * rc - r * r);
  EXPECT_NEAR(g.BoundaryDistanceM(mu), t, 1e-6);
  EXPECT_NEAR(g.PathTheta(1.0), 1.0, 1e-12);
  EXPECT_NEAR(g.PathTheta(0.0), 3500.0 / 211209.0, 1e-6);  // 0.01657
  EXPECT_NEAR(g.NormalisedDepth(1750.0, 1.0), 0.5, 1e-12);
  EXPECT_EQ(g.NormalisedDepth(1e9, 1.0), 1.0);
  EXPECT_EQ(g.NormalisedDepth(0.0, 1.0), 0.0);
  EXPECT_NEAR(FogGeometry::ElevationTheta(std::sin(30.0 * kPi / 180.0)), 1.0 / 3.0, 1e-12);
  EXPECT_THROW(FogGeometry(6371e3, 3500.0, 3500.0), UsageError);
  EXPECT_THROW(FogGeometry(0.0, 0.0, 3500.0), UsageError);
}

// A homogeneous low atmosphere of extinction sigma, uniformly lit: the fog to depth d is
// S (1 - e^{-sigma d})/sigma, so Fog(x)/Fog(1) = F(x, sigma D) exactly, and sigma D =
// sigma (c - h)/theta_path: the model with theta = path, p = -1, a = sigma (c - h) is exact in
// every direction, the horizon included (docs/fog.md, "Which θ").
TEST(FogModel, ExactForHomogeneousLowAtmosphereWithPathAngle) {
  const FogGeometry g = Earth();
  const double sigma = 1.0 / 20e3;  // 20 km of extinction length (visibility ~ 78 km, Koschmieder 3.912/sigma)
  const double a = sigma * 3500.0, p = -1.0;
  for (double mu : {0.0, 0.01, 0.1, 0.5, 1.0}) {
    const double D = g.BoundaryDistanceM(mu);
    for (double x : {0.001, 0.01, 0.1, 0.5, 0.9}) {
      const double exact = -std::expm1(-sigma * x * D) / -std::expm1(-sigma * D);
      const double model = DepthFactor(x, DepthExponent(a, p, g.PathTheta(mu)));
      EXPECT_NEAR(model, exact, 1e-12 * exact) << mu << " " << x;
    }
  }
}

// Attenuation LUT coordinates (the talk: u = pow(normalized depth, 1/3), v = pow(normalized
// theta, 1/2)): u = x^(1/3), v = (elevation / 90 deg)^(1/2), and their inverses.
TEST(FogModel, AttenuationCoordinates) {
  for (double x : {0.0, 1e-6, 0.125, 0.5, 1.0}) EXPECT_NEAR(DepthOfU(AttenuationU(x)), x, 1e-15);
  EXPECT_NEAR(AttenuationU(0.125), 0.5, 1e-15);
  for (double mu : {0.0, 0.01, 0.5, 0.9, 1.0}) EXPECT_NEAR(MuOfV(AttenuationV(mu)), mu, 1e-12);
  EXPECT_NEAR(AttenuationV(std::sin(22.5 * kPi / 180.0)), 0.5, 1e-12);
  EXPECT_EQ(AttenuationV(-0.5), 0.0);
}
