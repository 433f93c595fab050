// GT7's global fog model: the runtime math that rebuilds fog from a direction-only LUT and two
// fitted parameters (GT7 sky talk, "Fog", "Global Fog Approximation",
// "Global Fog Problem (1)/(2)"; docs/fog.md has the derivations and the measured errors).
//
// Geometry (local frame of lut/directions.h: +z zenith). The observer is at radius
// r = R + h (R the planet radius, h the observer altitude); the "low atmosphere" is the shell
// below the cut radius r_c = R + c (c the cut altitude: below the cloud base; docs/fog.md,
// "The cut"). A view direction with zenith cosine mu is first clamped to the horizon,
//   mu_c = max(mu, 0)                                                    (docs/fog.md, "The model")
// and its boundary distance is the path from the observer to the cut sphere,
//   D(mu) = -r mu_c + sqrt(r^2 mu_c^2 + r_c^2 - r^2)                  (ray-sphere, far root)
// (D(1) = c - h straight up, D(0) = sqrt(r_c^2 - r^2) along the horizon: 112.9 km for c = 1 km,
// 211.2 km for c = 3.5 km).
// An object at distance d (m) along the view has the normalised depth
//   x = min(d / D(mu), 1)                                               (the talk's "normalized depth")
// and the fog (radiance in-scattered between the observer and the object) is modelled as
//   Fog(mu, phi, d) = LUT(mu, phi) F(x, k),   k = a theta^p,
//   F(x, k) = (1 - exp(-k x)) / (1 - exp(-k))                         (the talk's equation)
// with LUT = the fog of the whole segment (x = 1) and theta the normalised view angle:
//   elevation:  theta = asin(mu_c) / (pi/2)                             (the talk's "normalized theta")
//   path:       theta = (r_c - r) / D(mu)  = sin(elevation) on a flat planet, (c - h)/D(0) = 0.0089
//               at the horizon for c = 1 km (skybake's default cut; docs/fog.md, "Which θ")
// For a homogeneous low atmosphere of extinction sigma lit uniformly, Fog(x)/Fog(1) is exactly
// F(x, sigma D) and sigma D = sigma (c - h) / theta_path: the model with theta_path, p = -1 and
// a = sigma (c - h) is exact, on the sphere and at the horizon; with theta_elevation it diverges
// at the horizon (k -> infinity as theta -> 0 when p < 0), which is the talk's model's failure
// near the horizon that docs/fog.md measures.
//
// The attenuation LUT (the talk: "u = pow(normalized depth, 1/3), v = pow(normalized theta,
// 1/2)") uses u = x^(1/3) and v = theta_elevation^(1/2) (always the elevation, so that the
// horizon gets the densest rows whatever the fit's theta is); its texels are nodes at both ends,
// texel i of N at u = i / (N - 1) (docs/fog.md, "Texel grid of the fog LUT").
#pragma once

#include <optional>
#include <string>

namespace skybake::fog {

// Which normalised view angle multiplies a in k = a theta^p.
enum class AngleDefinition { kElevation, kPath };
const char* AngleDefinitionName(AngleDefinition a);
std::optional<AngleDefinition> ParseAngleDefinition(const std::string& name);

// The smallest theta used in k = a theta^p (1e-6, 5.7e-5 deg of elevation): keeps log(theta)
// finite at the horizon; with p < 0 the exponent there is then large but finite, and F stays in
// [0, 1] (it tends to the step function 1 for x > 0).
inline constexpr double kThetaFloor = 1e-6;
// The largest exponent k used (exp(-1e6) = 0 in double: F is the step function beyond it).
inline constexpr double kMaxExponent = 1e6;

class FogGeometry {
 public:
  // UsageError unless R > 0, h >= 0 and c >= h + 1 m (a segment of at least a metre straight up).
  FogGeometry(double planet_radius_m, double observer_altitude_m, double cut_altitude_m);

  double planet_radius_m() const { return planet_radius_m_; }
  double observer_altitude_m() const { return observer_altitude_m_; }
  double cut_altitude_m() const { return cut_altitude_m_; }
  double observer_radius_m() const { return planet_radius_m_ + observer_altitude_m_; }
  double cut_radius_m() const { return planet_radius_m_ + cut_altitude_m_; }

  // mu_c = max(mu, 0), clamped to [0, 1].
  static double ClampedMu(double mu);
  // D(mu), m.
  double BoundaryDistanceM(double mu) const;
  // x = min(d / D(mu), 1), 0 for d <= 0.
  double NormalisedDepth(double depth_m, double mu) const;
  // theta_elevation = asin(mu_c) / (pi/2) in [0, 1]; its inverse mu = sin(theta pi/2).
  static double ElevationTheta(double mu);
  static double MuOfElevationTheta(double theta);
  // theta_path = (r_c - r) / D(mu) in [(c - h)/D(0), 1].
  double PathTheta(double mu) const;
  double Theta(AngleDefinition a, double mu) const;

 private:
  double planet_radius_m_, observer_altitude_m_, cut_altitude_m_;
};

// k = a theta^p with theta clamped to [kThetaFloor, 1] and k to [0, kMaxExponent]; a > 0.
double DepthExponent(double a, double p, double theta);

// F(x, k) = (1 - e^{-k x}) / (1 - e^{-k}) for x in [0, 1] (clamped), k in [0, inf]: evaluated as
// expm1(-k x) / expm1(-k), with the series x (1 + k (1 - x)/2) for k < 1e-8 (the k -> 0 limit is
// F = x, the optically thin segment). Always in [0, 1], monotone in x, F(0) = 0, F(1) = 1.
double DepthFactor(double x, double k);
// dF/dk (for the fit's Jacobian): (x e^{-kx} (1 - e^{-k}) - (1 - e^{-kx}) e^{-k}) / (1 - e^{-k})^2,
// with the series x [(1 - x)/2 + k (1/6 - x/2 + x^2/3)] for k < 1e-4 (the direct form loses
// ~log10(1/k) digits to cancellation there).
double DepthFactorDk(double x, double k);

// Attenuation LUT coordinates (nodes at both ends; docs/fog.md):
//   u = x^(1/3), v = theta_elevation^(1/2); texel (i, j) of N x M at u = i/(N-1), v = j/(M-1).
double AttenuationU(double x);
double AttenuationV(double mu);
double DepthOfU(double u);          // x = u^3
double MuOfV(double v);             // mu = sin(v^2 pi/2)

}  // namespace skybake::fog
