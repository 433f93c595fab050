// The `ms-approx` sky method: single scattering (the `single` march, transport/method_single.h)
// plus Hillaire's (2020) approximation of all higher orders ("A Scalable and Production Ready
// Sky and Atmosphere Rendering Technique", EGSR 2020, CGF 39(4), §5.5; reference shaders
// sebh/UnrealEngineSkyAtmosphere, RenderSkyRayMarching.hlsl NewMultiScattCS). docs/sky-methods.md
// has the derivation and the measured errors.
//
// At every point x of altitude z, the light scattered two or more times is assumed to arrive
// isotropically and to depend only on (z, mu_s), the sun's zenith cosine at x. Per wavelength and
// per unit solar irradiance (E_0 = 1):
//   L_2nd(z, mu_s) = 1/(4 pi) int_{4 pi} L'(x, w) dw                                  (eq. 5)
//     L'(x, w) = int_0^l T(x, x_t) sigma_s(x_t) (1/(4 pi)) V T_sun(x_t) dt            (eq. 6)
//                + T(x, x_l) (a/pi) mu_g T_sun(x_l)   [rays that end on the ground]
//   f_ms(z, mu_s)  = 1/(4 pi) int_{4 pi} int_0^l T(x, x_t) sigma_s(x_t) dt dw          (eq. 7-8)
//   Psi_ms = L_2nd (1 + f_ms + f_ms^2 + ...) = L_2nd / (1 - f_ms)                      (eq. 9-10)
// f_ms is the fraction of isotropically emitted light that the surroundings scatter back to x,
// so each further order is the previous one times f_ms (the geometric series). The view-ray
// source then gains sigma_s(x) Psi_ms(z, mu_s) E_0 (eq. 11). The isotropic phase in L' and f_ms is
// the method's approximation (exact for isotropic scatterers in a medium that is homogeneous
// around x); its error grows with the aerosols' asymmetry and density (Hillaire 2020 §7: RMSE
// 0.0058 at g = 0 vs 0.039 at g = 0.8 in a dense Mie medium).
//
// The LUT: Psi_ms on n_mu_s x n_z nodes (mu_s in [-1, 1], z in [0, top], both linear with nodes
// at the ends, as the paper's 32 x 32 texture), bilinear. Each node integrates the sphere with
// sqrt_dirs^2 stratified directions (azimuth 2 pi (i + 1/2)/n, cos(zenith) 1 - 2 (j + 1/2)/n: the
// paper's 8 x 8 = 64), computed for the half-sphere y >= 0 and mirrored (the field is symmetric
// about the sun's vertical plane). The rays are integrated with the `single` march (altitude
// ladder, linear-exponential rule, exact shadow geometry) at a coarser ladder; the paper uses 20
// uniform steps, which undersample the 1.2 km aerosol layer on 1000 km grazing rays.
//
// `SkyMethodOptions::orders` > 0 truncates the series: orders = 1 is `single`; N >= 2 keeps
// L_2nd (1 + f + ... + f^{N-2}) (the "capped orders" simplification of docs/sky-methods.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "io/progress.h"
#include "transport/method_single.h"
#include "transport/sky_method.h"

namespace skybake {

struct MsApproxSettings {
  MarchSettings march;        // the view rays (as `single` at the same quality)
  int lut_mu_s = 32;          // LUT nodes in the sun zenith cosine
  int lut_z = 32;             // ... and in altitude
  int sqrt_dirs = 8;          // directions per LUT node: sqrt_dirs^2
  double ray_dz_min_m = 300;  // the LUT rays' altitude ladder and longest piece
  double ray_dz_rel = 0.25;
  double ray_max_piece_m = 50e3;
  int orders = 0;             // 0: all (the geometric series); N: orders 1..N
};

// The presets, indexed by quality.
const QualityTable<MsApproxSettings>& MsApproxPresets();
MsApproxSettings MsApproxPreset(Quality quality);

class MultipleScatteringLut : public SingleScatteringModel::ExtraSource {
 public:
  MultipleScatteringLut(const SingleScatteringModel& ss, const MsApproxSettings& settings, const ProgressFn& progress);
  // Psi_ms per unit solar irradiance (sr^-1 m: radiance per unit irradiance and unit scattering
  // coefficient) at altitude z and sun zenith cosine mu_s, bilinear, into psi[wl].
  void Psi(double z_m, double mu_s, double* psi) const;
  // The node values (for tests): L_2nd and f_ms at node (i_mu, i_z).
  const std::vector<double>& l2() const { return l2_; }
  const std::vector<double>& fms() const { return fms_; }
  void Add(double z_m, double mu_sun, const double* sigma_s, double* src) const override;

 private:
  void Accumulate(double z_m, double mu_s, const double* scale, double* dst) const;
  const SingleScatteringModel& ss_;
  MsApproxSettings s_;
  size_t nw_;
  double top_;
  std::vector<double> psi_, l2_, fms_;  // [(i_z * n_mu + i_mu) * nw + wl]
};

std::unique_ptr<SkyMethod> MakeMsApproxMethod(const AtmosphereModel& model, const SkyMethodOptions& options,
                                              const ProgressFn& progress);
// With explicit settings (tests, the budget).
std::unique_ptr<SkyMethod> MakeMsApproxMethod(const AtmosphereModel& model, const MsApproxSettings& settings,
                                              const ProgressFn& progress);

}  // namespace skybake
