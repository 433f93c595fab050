#include "fog/fog_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "atmosphere/ray_sphere.h"
#include "io/error.h"

namespace skybake::fog {

namespace {
constexpr double kHalfPi = std::numbers::pi / 2.0;
}

const char* AngleDefinitionName(AngleDefinition a) { return a == AngleDefinition::kPath ? "path" : "elevation"; }

std::optional<AngleDefinition> ParseAngleDefinition(const std::string& name) {
  if (name == "path") return AngleDefinition::kPath;
  if (name == "elevation") return AngleDefinition::kElevation;
  return std::nullopt;
}

FogGeometry::FogGeometry(double planet_radius_m, double observer_altitude_m, double cut_altitude_m)
    : planet_radius_m_(planet_radius_m), observer_altitude_m_(observer_altitude_m), cut_altitude_m_(cut_altitude_m) {
  if (!(planet_radius_m > 0.0) || !std::isfinite(planet_radius_m)) {
    throw UsageError(fmt::format("fog: the planet radius must be positive, got {} m", planet_radius_m));
  }
  if (!(observer_altitude_m >= 0.0) || !std::isfinite(observer_altitude_m)) {
    throw UsageError(fmt::format("fog: the observer altitude must be >= 0, got {} m", observer_altitude_m));
  }
  if (!(cut_altitude_m >= observer_altitude_m + 1.0) || !std::isfinite(cut_altitude_m)) {
    throw UsageError(fmt::format("fog: the cut altitude ({} m) must be at least 1 m above the observer ({} m)",
                                 cut_altitude_m, observer_altitude_m));
  }
}

double FogGeometry::ClampedMu(double mu) { return std::isfinite(mu) ? std::clamp(mu, 0.0, 1.0) : 0.0; }

double FogGeometry::BoundaryDistanceM(double mu) const {
  // The far root in its rationalised form: no cancellation looking up (r mu >> r_c - r).
  return DistanceToSphereOutStable(observer_radius_m(), ClampedMu(mu), cut_radius_m());
}

double FogGeometry::NormalisedDepth(double depth_m, double mu) const {
  if (!(depth_m > 0.0)) return 0.0;
  return std::min(1.0, depth_m / BoundaryDistanceM(mu));
}

double FogGeometry::ElevationTheta(double mu) { return std::asin(ClampedMu(mu)) / kHalfPi; }

double FogGeometry::MuOfElevationTheta(double theta) { return std::sin(std::clamp(theta, 0.0, 1.0) * kHalfPi); }

double FogGeometry::PathTheta(double mu) const {
  return std::min(1.0, (cut_radius_m() - observer_radius_m()) / BoundaryDistanceM(mu));
}

double FogGeometry::Theta(AngleDefinition a, double mu) const {
  return a == AngleDefinition::kPath ? PathTheta(mu) : ElevationTheta(mu);
}

double DepthExponent(double a, double p, double theta) {
  const double t = std::clamp(std::isfinite(theta) ? theta : 0.0, kThetaFloor, 1.0);
  const double k = a * std::exp(p * std::log(t));
  if (!(k > 0.0)) return 0.0;  // also NaN
  return std::min(k, kMaxExponent);
}

double DepthFactor(double x, double k) {
  if (!(x > 0.0)) return 0.0;
  if (x >= 1.0) return 1.0;
  if (!(k > 0.0)) return x;
  if (k < 1e-8) return x * (1.0 + 0.5 * k * (1.0 - x));
  if (k >= kMaxExponent) return 1.0 - std::exp(-k * x);  // exp(-k) = 0 here
  return std::clamp(std::expm1(-k * x) / std::expm1(-k), 0.0, 1.0);
}

double DepthFactorDk(double x, double k) {
  if (!(x > 0.0) || x >= 1.0) return 0.0;
  if (!(k > 0.0)) k = 0.0;
  if (k < 1e-4) return x * (0.5 * (1.0 - x) + k * (1.0 / 6.0 - 0.5 * x + x * x / 3.0));
  const double e = std::exp(-k), ex = std::exp(-k * x);
  const double g = -std::expm1(-k), gx = -std::expm1(-k * x);
  return (x * ex * g - gx * e) / (g * g);
}

double AttenuationU(double x) { return std::cbrt(std::clamp(x, 0.0, 1.0)); }
double AttenuationV(double mu) { return std::sqrt(FogGeometry::ElevationTheta(mu)); }
double DepthOfU(double u) {
  const double c = std::clamp(u, 0.0, 1.0);
  return c * c * c;
}
double MuOfV(double v) {
  const double c = std::clamp(v, 0.0, 1.0);
  return FogGeometry::MuOfElevationTheta(c * c);
}

}  // namespace skybake::fog
