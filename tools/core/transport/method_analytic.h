// The `analytic` sky method: the Cloud Party approximation (the Cloud Party sky articles on
// Gamasutra, part 2 of 3, "Improved Implementation"), a real-time shader's
// single scattering in a *constant-density* atmosphere shell, applied to the model's own
// coefficients and phase functions (docs/sky-methods.md, "analytic").
//
// The model's medium is replaced by constant coefficients in the shell R < r < R_top with the
// same vertical columns (so the zenith transmittance is exact):
//   beta_s,c(lambda) = int_0^top sigma_s,c(z, lambda) dz / top,   beta_e = sum_c (beta_s,c + beta_a,c)
// With d(p, w) = sqrt((p.w)^2 + R_top^2 - |p|^2) - p.w the distance from p along w to the top
// (the blog's opticalDepth(): the planet is ignored, so there is no Earth shadow), the view ray
// of length d_v (to the top, or to the ground: our extension, see below) and
//   F(nu) = sum_c beta_s,c P_c(nu) / beta_e           (the blog's calcScattering)
// the two formulas of the blog are:
//  - "Improved Implementation" (steps = 0; quality low): one point stands for the whole ray,
//      k  = 0.15 + 0.75 mu_s                        (mu_s: the sun's zenith cosine at the viewer)
//      d_l = max(d(x + k d_v v, s), d(x + d_v v, s))
//      L  = E_0 e^{-beta_e d_l} F(nu) (1 - e^{-beta_e d_v})
//    i.e. the exact constant-density integral with the sun's transmittance frozen at one point.
//  - "Initial Implementation" (steps = N; qualities medium N = 20, the blog's NUM_STEPS, and high
//    N = 200, the converged constant-density model): a march with the light sampled at the start
//    of each step and the step's extinction integrated exactly:
//      L = sum_{i<N} E_0 e^{-beta_e d(x + i D v, s)} F(nu) (1 - e^{-beta_e D}) e^{-beta_e i D},  D = d_v/N.
//    (The blog loops i <= NUM_STEPS, one step past the end of the ray; we take N steps.)
// Deviations from the blog, on purpose (docs/sky-methods.md lists them): the phase functions are
// the model's (the blog's HG numerator (1 - g)^2 is not normalised: it underestimates the Mie
// phase by (1 + g)/(1 - g) = 7 at its g = 0.75), the coefficients are the model's columns (not
// the blog's lambda^-4 / lambda^-2 fits), and view rays below the horizon end on the ground (the
// blog draws the sky only where no geometry is; it adds no ground reflection and neither do we).
// Known failures (measured in docs/sky-methods.md): no Earth shadow (twilight), the horizon (a
// uniform 100 km shell has a horizontal air mass of ~11 instead of ~38 for air and ~90 for the
// 1.2 km aerosol layer), no multiple scattering.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "atmosphere/model.h"
#include "transport/sky_method.h"

namespace skybake {

class AnalyticSky {
 public:
  explicit AnalyticSky(const AtmosphereModel& model);
  // The constant coefficients (m^-1) per wavelength.
  const std::vector<double>& extinction() const { return beta_e_; }
  const std::vector<std::vector<double>>& scattering() const { return beta_s_; }
  // The blog's distance from p (planet-centred, m) along unit w to the top of the atmosphere.
  double DistanceToTop(const glm::dvec3& p, const glm::dvec3& w) const;
  // Spectral radiance (W m^-2 sr^-1 nm^-1) at x along unit v for the sun along unit `sun`
  // (mu_s is taken at x); steps = 0: the improved one-point formula; N > 0: the N-step march.
  void Radiance(const glm::dvec3& x, const glm::dvec3& v, const glm::dvec3& sun, int steps, double* L) const;

 private:
  const AtmosphereModel& model_;
  std::vector<double> beta_e_;
  std::vector<std::vector<double>> beta_s_;  // per scattering component
  std::vector<const PhaseModel*> phase_;
};

// The presets: march steps along the view ray by quality (0: the improved, one-point formula).
const QualityTable<int>& AnalyticSteps();

std::unique_ptr<SkyMethod> MakeAnalyticMethod(const AtmosphereModel& model, const SkyMethodOptions& options);

}  // namespace skybake
