// The ray-sphere geometry (atmosphere/ray_sphere.h) against closed forms: the zenith, nadir and
// horizontal rays, the tangent ray, a ray from outside the atmosphere, the conservation of r mu + d
// and of the impact parameter along a ray, and the two spellings (r, mu) and (b, r2) agreeing.
// Radii of the Earth (R = 6360 km) and of the top of the atmosphere (6420 km): Bruneton 2017's
// demo atmosphere (`atmosphere/demo/demo.cc`, kBottomRadius, kTopRadius).
#include <gtest/gtest.h>

#include <cmath>

#include "atmosphere/ray_sphere.h"

using namespace skybake;

namespace {
constexpr double kR = 6360e3, kTop = 6420e3;  // m
// A length tolerance (m): 1e-6 m is ~1000 ulp of a radius of 6.4e6 m (ulp 9.3e-10 m).
constexpr double kTolM = 1e-6;
}  // namespace

// Straight up from radius r: the top is rho - r away; straight down the ground is r - R away.
TEST(RaySphere, ZenithAndNadir) {
  for (double h : {0.0, 1.0, 1000.0, 30e3, 59e3}) {
    const double r = kR + h;
    EXPECT_NEAR(DistanceToSphereOut(r, 1.0, kTop), kTop - r, kTolM) << h;
    EXPECT_NEAR(DistanceToTopAtmosphereBoundary(r, 1.0, kTop), kTop - r, kTolM) << h;
    EXPECT_NEAR(DistanceToSphereOutStable(r, 1.0, kTop), kTop - r, kTolM) << h;
    EXPECT_NEAR(DistanceToSphereOutStableR2Mu2(r, 1.0, kTop), kTop - r, kTolM) << h;
    EXPECT_FALSE(RayIntersectsGround(r, 1.0, kR));
    // Down: the ray hits the ground at r - R (for h > 0), the top behind it at r + top.
    if (h > 0.0) {
      EXPECT_TRUE(RayIntersectsGround(r, -1.0, kR)) << h;
      EXPECT_NEAR(DistanceToSphereIn(r, -1.0, kR), h, kTolM) << h;
      EXPECT_NEAR(DistanceToNearestBoundary(r, -1.0, kR, kTop, true), h, kTolM) << h;
    }
    EXPECT_NEAR(DistanceToSphereOut(r, -1.0, kTop), r + kTop, kTolM) << h;
    EXPECT_NEAR(DistanceToSphereOutStable(r, -1.0, kTop), r + kTop, kTolM) << h;
  }
}

// Along the local horizontal (mu = 0) the top is sqrt(top^2 - r^2) away (Pythagoras).
TEST(RaySphere, HorizontalRay) {
  for (double h : {0.0, 10e3, 50e3}) {
    const double r = kR + h;
    const double expect = std::sqrt((kTop - r) * (kTop + r));
    EXPECT_NEAR(DistanceToSphereOut(r, 0.0, kTop), expect, kTolM);
    EXPECT_NEAR(DistanceToSphereOutStable(r, 0.0, kTop), expect, kTolM);
    EXPECT_NEAR(DistanceToSphereOutDot(0.0, r * r, kTop), expect, kTolM);
    EXPECT_FALSE(RayIntersectsGround(r, 0.0, kR));
  }
}

// The tangent ray to the ground: mu_h = -sqrt(1 - (R/r)^2), the tangent point sqrt(r^2 - R^2)
// away (the distance to the horizon); rays just below it hit the ground, just above it miss; the
// clamped discriminant keeps the distance finite where Delta rounds below 0.
TEST(RaySphere, TangentToTheGround) {
  for (double h : {1.0, 100.0, 2000.0, 40e3}) {
    const double r = kR + h;
    const double mu_h = HorizonMu(r, kR);
    // 1 - (R/r)^2 cancels for a low observer: an ulp of 1 in it is 1e-13 of mu_h at h = 1 m.
    EXPECT_NEAR(mu_h, -std::sqrt(h * (2.0 * kR + h)) / r, 1e-12);
    EXPECT_NEAR(HorizonMuOfSquares(r, kR), mu_h, 1e-12);
    const double rho = DistanceToHorizon(r, kR);
    EXPECT_NEAR(rho, std::sqrt(h * (2.0 * kR + h)), kTolM);
    // |Delta| at the tangent is a rounding error of r^2 (~4e13 m^2, ulp 0.008 m^2).
    EXPECT_LT(std::abs(SphereDiscriminant(r, mu_h, kR)), 1.0);
    const double d = DistanceToSphereIn(r, mu_h, kR);
    EXPECT_TRUE(std::isfinite(d));
    // sqrt(|Delta|) <= 1 m of error at the tangent itself, where the root is a double root.
    EXPECT_NEAR(d, rho, 1.0);
    EXPECT_TRUE(RayIntersectsGround(r, mu_h - 1e-6, kR)) << h;
    EXPECT_FALSE(RayIntersectsGround(r, mu_h + 1e-6, kR)) << h;
    // The point at the tangent distance is on the ground, and the ray is horizontal there.
    const double r_d = RadiusAt(r, mu_h, rho);
    EXPECT_NEAR(r_d, kR, 1e-3);
    EXPECT_NEAR(MuAt(r, mu_h, rho, r_d), 0.0, 1e-9);
  }
  // From the ground itself the horizon is the local horizontal.
  EXPECT_EQ(HorizonMu(kR, kR), 0.0);
  EXPECT_EQ(DistanceToHorizon(kR, kR), 0.0);
}

// From outside the atmosphere (r > top): a ray aimed at the centre enters at r - top and leaves
// at r + top; a ray whose impact parameter exceeds the top misses (Delta < 0).
TEST(RaySphere, FromOutsideTheAtmosphere) {
  const double r = kTop + 100e3;
  EXPECT_GE(SphereDiscriminant(r, -1.0, kTop), 0.0);
  EXPECT_NEAR(DistanceToSphereIn(r, -1.0, kTop), r - kTop, kTolM);
  EXPECT_NEAR(DistanceToSphereOut(r, -1.0, kTop), r + kTop, kTolM);
  EXPECT_NEAR(DistanceToSphereInDot(-r, r * r, kTop), r - kTop, kTolM);
  // Grazing the top: impact parameter p = top exactly when sqrt(1 - mu^2) = top / r.
  const double mu_graze = -std::sqrt(1.0 - (kTop / r) * (kTop / r));
  EXPECT_LT(SphereDiscriminant(r, mu_graze + 1e-4, kTop), 0.0);
  EXPECT_GT(SphereDiscriminant(r, mu_graze - 1e-4, kTop), 0.0);
  EXPECT_LT(SphereDiscriminantDot(r * (mu_graze + 1e-4), r * r, kTop), 0.0);
  // Looking away from the planet: no entry ahead (both roots behind the start).
  EXPECT_LT(DistanceToSphereOut(r, 0.5, kTop), 0.0);
}

// Along any ray r_d mu_d = r mu + d and r_d sqrt(1 - mu_d^2) = r sqrt(1 - mu^2) (the impact
// parameter); the point at the exit distance lies on the sphere; the sun's cosine at d equals the
// one of the 3-D point x + d v.
TEST(RaySphere, InvariantsAlongARay) {
  // An arbitrary sun (zenith 1.1 rad, azimuth 0.7 rad); its y component does not enter, the ray
  // and its points lying in the x-z plane.
  const double sun_theta = 1.1, sun_phi = 0.7;
  const double sx = std::sin(sun_theta) * std::cos(sun_phi), sz = std::cos(sun_theta);
  for (double h : {0.0, 500.0, 8e3, 45e3}) {
    for (double mu : {-0.9, -0.2, -0.01, 0.0, 0.03, 0.4, 0.99}) {
      const double r = kR + h;
      if (h == 0.0 && mu < 0.0) continue;  // on the ground looking down: an empty ray
      const bool ground = RayIntersectsGround(r, mu, kR);
      const double length = DistanceToNearestBoundary(r, mu, kR, kTop, ground);
      ASSERT_GT(length, 0.0) << h << " " << mu;
      EXPECT_NEAR(RadiusAt(r, mu, length), ground ? kR : kTop, 1e-4) << h << " " << mu;
      const double vx = std::sqrt(1.0 - mu * mu), vz = mu;  // the ray in the x-z plane
      const double mu_s = sz, nu = vx * sx + vz * sz;
      for (double f : {0.1, 0.5, 0.9}) {
        const double d = f * length;
        const double r_d = RadiusAt(r, mu, d), mu_d = MuAt(r, mu, d, r_d);
        EXPECT_NEAR(r_d * mu_d, r * mu + d, kTolM);
        EXPECT_NEAR(r_d * std::sqrt(std::max(0.0, 1.0 - mu_d * mu_d)), r * std::sqrt(1.0 - mu * mu), 1e-3);
        EXPECT_NEAR(ImpactParameterSquared(r_d, mu_d), ImpactParameterSquared(r, mu), 1e-12 * r * r);
        // The 3-D point y = (d vx, 0, r + d vz).
        const double yx = d * vx, yz = r + d * vz;
        EXPECT_NEAR(r_d, std::hypot(yx, yz), kTolM);
        EXPECT_NEAR(SunMuAt(r, mu_s, nu, d, r_d), (yx * sx + yz * sz) / r_d, 1e-12);
      }
    }
  }
}

// The (b, r2) spelling gives the (r, mu) one's roots to rounding (an ulp of r^2 in Delta).
TEST(RaySphere, DotFormMatchesRadiusCosineForm) {
  for (double h : {0.0, 3e3, 59e3}) {
    for (double mu : {-1.0, -0.5, -0.05, 0.0, 0.2, 1.0}) {
      const double r = kR + h, b = r * mu, r2 = r * r;
      EXPECT_NEAR(DistanceToSphereOutDot(b, r2, kTop), DistanceToSphereOut(r, mu, kTop), 1e-4);
      if (RayIntersectsGround(r, mu, kR)) {
        EXPECT_GE(SphereDiscriminantDot(b, r2, kR), 0.0);
        EXPECT_NEAR(DistanceToSphereInDot(b, r2, kR), DistanceToSphereIn(r, mu, kR), 1e-4);
      }
    }
  }
}

// Looking up through a thin shell (rho - r = 1 mm above r = 6360 km): the rationalised root is
// exact to rounding, where -r mu + sqrt(Delta) loses the digits of r (an ulp of r is 9e-10 m,
// 1e-6 of the answer). Both stable spellings agree with it and with the plain root elsewhere.
TEST(RaySphere, StableRootWithoutCancellation) {
  const double r = kR, rho = kR + 1e-3;
  const double gap = rho - r;  // exact (Sterbenz): 1 mm to the rounding of rho
  EXPECT_NEAR(DistanceToSphereOutStable(r, 1.0, rho), gap, gap * 1e-12);
  EXPECT_NEAR(DistanceToSphereOutStableR2Mu2(r, 1.0, rho), gap, gap * 1e-12);
  // mu = 0.5: d = -r mu + sqrt(r^2 mu^2 + q) = q / (r mu + sqrt(r^2 mu^2 + q)), q = (rho - r)(rho + r).
  const double q = (rho - r) * (rho + r);
  EXPECT_NEAR(DistanceToSphereOutStable(r, 0.5, rho), q / (r * 0.5 + std::sqrt(r * r * 0.25 + q)), 1e-3 * 1e-13);
  for (double mu : {-1.0, -0.3, 0.0, 0.3, 1.0}) {
    const double a = DistanceToSphereOutStable(kR + 2e3, mu, kTop);
    EXPECT_NEAR(a, DistanceToSphereOut(kR + 2e3, mu, kTop), 1e-4) << mu;
    EXPECT_NEAR(DistanceToSphereOutStableR2Mu2(kR + 2e3, mu, kTop), a, 1e-6) << mu;
  }
}

// At the top looking out the far root is 0, up to the cancellation of -r mu + sqrt(Delta): at
// mu = 1e-9, r^2 mu^2 = 4e-5 m^2 is below an ulp of Delta's terms (0.008 m^2) and the plain root
// is -r mu = -6 mm. Bruneton's DistanceToTopAtmosphereBoundary clamps it at 0; the stable root is 0.
TEST(RaySphere, ClampsAtTheTop) {
  for (double mu : {0.0, 1e-9, 0.3, 1.0}) {
    EXPECT_GE(DistanceToTopAtmosphereBoundary(kTop, mu, kTop), 0.0) << mu;
    EXPECT_NEAR(DistanceToSphereOut(kTop, mu, kTop), 0.0, 0.01) << mu;
    if (mu > 0.0) {
      EXPECT_EQ(DistanceToSphereOutStable(kTop, mu, kTop), 0.0) << mu;
    }
  }
  EXPECT_EQ(ClampCosine(1.0 + 1e-15), 1.0);
  EXPECT_EQ(ClampCosine(-1.5), -1.0);
  EXPECT_EQ(ClampDistance(-1e-9), 0.0);
  EXPECT_EQ(SafeSqrt(-1e-3), 0.0);
}
