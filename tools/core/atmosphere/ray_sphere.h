// The geometry of a ray in a spherically symmetric atmosphere: the distances along a ray to a
// sphere centred on the planet (the ground, the top of the atmosphere, a cut altitude), whether
// the ray hits the ground, and the radius and cosines at a distance d along it. Every method
// (single scattering and the marcher it shares, orders, analytic, the path tracer), the fog
// model and the GT7 time mapping take their ray-sphere geometry from here.
//
// A ray starts at radius r (m, from the planet centre) with direction cosine mu to the local
// zenith. Its point at distance d (m) has, by the law of cosines,
//   r_d^2 = d^2 + 2 r mu d + r^2,   mu_d = (r mu + d) / r_d,   mu_s,d = (r mu_s + d nu) / r_d
// (mu_s the sun's cosine at the start, nu the cosine between ray and sun), and the sphere of
// radius rho is met where r_d = rho:
//   d = -r mu +- sqrt(Delta),   Delta = r^2 (mu^2 - 1) + rho^2
// (Bruneton & Neyret 2008 "Precomputed Atmospheric Scattering" §4; Bruneton 2017,
// `atmosphere/functions.glsl`, DistanceToTopAtmosphereBoundary, DistanceToBottomAtmosphereBoundary,
// RayIntersectsGround, ComputeSingleScatteringIntegrand). The far root (+) is the exit from inside
// the sphere, the near root (-) the entry from outside. Along the ray the impact parameter is
// conserved, r_d sqrt(1 - mu_d^2) = r sqrt(1 - mu^2), and r_d mu_d = r mu + d.
//
// Numerics: Delta is clamped at 0 before its square root (SafeSqrt, Bruneton 2017), so that a
// tangent ray whose Delta rounds below 0 gets the tangent distance instead of NaN. The roots
// -r mu + sqrt(Delta) cancel for a ray looking up (r mu >> rho - r): DistanceToSphereOutStable
// is the rationalised form (rho^2 - r^2) / (r mu + sqrt(Delta)) with rho^2 - r^2 = (rho - r)(rho + r),
// exact to a few ulp at every mu. The plain forms are kept where their results are the products'
// bytes: each function's expression order is the one its callers compute (the build has
// -ffp-contract=off, so an inline function rounds as the expression written at the call site).
//
// Two spellings of the same roots exist because the callers hold different data:
//  - (r, mu): the radius and cosine (the orders tables and renders, the view segments, the
//    single-scattering transmittance table);
//  - "Dot" (b, r2): b = x.v = r mu and r2 = x.x = r^2 for a position vector x and unit direction v,
//    Delta = b^2 - (r2 - rho^2): the 3-D marchers and the path tracer, which need no |x| (a square
//    root) or mu = b / |x| (a division) for it.
// The two round differently (r^2 (mu^2 - 1) + rho^2 against b^2 - (r^2 - rho^2)), by an ulp of r^2.
#pragma once

#include <algorithm>
#include <cmath>

namespace skybake {

// sqrt(max(a, 0)): a discriminant that rounds below 0 at a tangent gives 0 (Bruneton 2017, SafeSqrt).
inline double SafeSqrt(double a) { return std::sqrt(std::max(0.0, a)); }

// max(d, 0) (Bruneton 2017, ClampDistance).
inline double ClampDistance(double d) { return std::max(0.0, d); }

// clamp(mu, -1, 1) (Bruneton 2017, ClampCosine).
inline double ClampCosine(double mu) { return std::clamp(mu, -1.0, 1.0); }

// ------------------------------------------------------------------------ the (r, mu) form

// Delta = r^2 (mu^2 - 1) + rho^2 (m^2): >= 0 iff the ray's line meets the sphere of radius rho.
inline double SphereDiscriminant(double r, double mu, double rho) { return r * r * (mu * mu - 1.0) + rho * rho; }

// The far root -r mu + sqrt(max(Delta, 0)) (m): from inside the sphere (r <= rho), the distance to
// where the ray leaves it. Not clamped: for r = rho and mu >= 0 it can round to a few ulp below 0,
// which the callers treat as an empty ray (orders/rays.cpp, orders/render.cpp: length <= 0).
inline double DistanceToSphereOut(double r, double mu, double rho) {
  return -r * mu + SafeSqrt(SphereDiscriminant(r, mu, rho));
}

// The near root -r mu - sqrt(max(Delta, 0)) (m): the distance to where the ray enters the sphere
// from outside (r >= rho), meaningful where RayIntersectsGround (or Delta >= 0 and mu < 0).
inline double DistanceToSphereIn(double r, double mu, double rho) {
  return -r * mu - SafeSqrt(SphereDiscriminant(r, mu, rho));
}

// Bruneton 2017, DistanceToTopAtmosphereBoundary: the far root clamped at 0, for r <= top.
inline double DistanceToTopAtmosphereBoundary(double r, double mu, double top_radius_m) {
  return ClampDistance(DistanceToSphereOut(r, mu, top_radius_m));
}

// Bruneton 2017, RayIntersectsGround: mu < 0 and Delta(bottom) >= 0, for r >= bottom.
inline bool RayIntersectsGround(double r, double mu, double bottom_radius_m) {
  return mu < 0.0 && SphereDiscriminant(r, mu, bottom_radius_m) >= 0.0;
}

// Bruneton 2017, DistanceToNearestAtmosphereBoundary, unclamped (DistanceToSphereOut): the
// distance to the ground if the ray hits it, else to the top of the atmosphere.
inline double DistanceToNearestBoundary(double r, double mu, double bottom_radius_m, double top_radius_m,
                                        bool intersects_ground) {
  return intersects_ground ? DistanceToSphereIn(r, mu, bottom_radius_m) : DistanceToSphereOut(r, mu, top_radius_m);
}

// r_d = sqrt(r^2 + 2 r mu d + d^2) (m): the radius at distance d along the ray (Bruneton 2017,
// ComputeSingleScatteringIntegrand, there summed from d^2; here from r^2, the callers' order).
inline double RadiusAt(double r, double mu, double d) { return std::sqrt(r * r + 2.0 * r * mu * d + d * d); }

// mu_d = (r mu + d) / r_d: the ray's zenith cosine at distance d, r_d = RadiusAt(r, mu, d)
// (unclamped: it can exceed 1 by an ulp; ClampCosine where a cosine must be one).
inline double MuAt(double r, double mu, double d, double r_d) { return (r * mu + d) / r_d; }

// mu_s,d = (r mu_s + d nu) / r_d: the sun's zenith cosine at distance d (Bruneton 2017,
// ComputeSingleScatteringIntegrand), mu_s the sun's cosine at the start, nu = cos(ray, sun).
inline double SunMuAt(double r, double mu_s, double nu, double d, double r_d) { return (r * mu_s + d * nu) / r_d; }

// p^2 = max(0, r^2 (1 - mu^2)) (m^2): the squared impact parameter (the ray's closest distance to
// the centre), conserved along the ray: r_d^2 = p^2 + (r mu + d)^2.
inline double ImpactParameterSquared(double r, double mu) { return std::max(0.0, r * r * (1.0 - mu * mu)); }

// rho = sqrt(max(0, r^2 - R^2)) (m): the distance from radius r to the horizon of the sphere R
// (the tangent ray's length; Bruneton 2017, GetTransmittanceTextureUvFromRMu's rho and H).
inline double DistanceToHorizon(double r, double bottom_radius_m) { return SafeSqrt(r * r - bottom_radius_m * bottom_radius_m); }

// mu_h = -sqrt(max(0, 1 - (R/r)^2)): the cosine of the horizon seen from radius r >= R (Bruneton &
// Neyret 2008 §4): rays with mu < mu_h hit the ground.
inline double HorizonMu(double r, double bottom_radius_m) {
  const double q = bottom_radius_m / r;
  return -SafeSqrt(1.0 - q * q);
}

// The same cosine as -sqrt(max(0, 1 - R^2 / r^2)): the single-scattering method's transmittance
// table and ground irradiance use this rounding (transport/method_single.cpp).
inline double HorizonMuOfSquares(double r, double bottom_radius_m) {
  return -SafeSqrt(1.0 - (bottom_radius_m * bottom_radius_m) / (r * r));
}

// The far root without cancellation, for r < rho (at r = rho and mu = 0 it is 0/0): with q = (rho - r)(rho + r) = rho^2 - r^2 and
// b = r mu, d = q / (b + sqrt(b^2 + q)) for mu >= 0 (the rationalised -b + sqrt(b^2 + q)), and
// sqrt(b^2 + q) - b for mu < 0 (no cancellation there). Used by the fog model's distance to the
// cut altitude (fog/fog_model.cpp).
inline double DistanceToSphereOutStable(double r, double mu, double rho) {
  const double q = (rho - r) * (rho + r);
  const double b = r * mu;
  const double root = std::sqrt(b * b + q);
  return mu >= 0.0 ? q / (b + root) : root - b;
}

// The same root with b^2 spelt r^2 mu^2 (((r r) mu) mu): the GT7 time mapping's slice distances
// (lut/gt7_mapping.cpp), whose texel positions lut-pack's outputs hold; it differs from
// DistanceToSphereOutStable by an ulp of b^2.
inline double DistanceToSphereOutStableR2Mu2(double r, double mu, double rho) {
  const double q = (rho - r) * (rho + r);
  const double root = std::sqrt(r * r * mu * mu + q);
  return mu >= 0.0 ? q / (root + r * mu) : root - r * mu;
}

// ------------------------------------------------------------------------ the Dot form

// Delta = b^2 - (r2 - rho^2) (m^2) with b = x.v, r2 = x.x.
inline double SphereDiscriminantDot(double b, double r2, double rho) { return b * b - (r2 - rho * rho); }

// The far root -b + sqrt(max(Delta, 0)) (m), unclamped.
inline double DistanceToSphereOutDot(double b, double r2, double rho) { return -b + SafeSqrt(SphereDiscriminantDot(b, r2, rho)); }

// The near root -b - sqrt(max(Delta, 0)) (m), meaningful where Delta >= 0.
inline double DistanceToSphereInDot(double b, double r2, double rho) { return -b - SafeSqrt(SphereDiscriminantDot(b, r2, rho)); }

}  // namespace skybake
