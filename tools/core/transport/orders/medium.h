// The medium of `orders` per model level, wavelength innermost (float): extinction and scattering
// coefficients of the true and of the delta-scaled medium (sigma_s* = (1 - f) sigma_s, Potter 1970
// truncation in Wiscombe 1977's delta-M sense), each component's truncation cone and truncated
// phase function on a uniform grid in cos(theta).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "atmosphere/model.h"
#include "transport/orders/settings.h"

namespace skybake::orders {

struct Medium {
  const AtmosphereModel* m = nullptr;
  size_t nw = 0;
  // The reference wavelength of the table rays' step placement and of the solve's stopping rule:
  // the grid's middle one, at this index (a wavelength batch, SliceMedium, keeps it).
  size_t wref = 0;
  size_t nc = 0;  // scattering components
  // Per model level l: sigma_t[l*nw+w], sigma_t*[..], sigma_s_c[(c*nl+l)*nw+w], sigma_s*_c.
  std::vector<float> sigma_t, sigma_t_star, sigma_s, sigma_s_star;
  std::vector<float> sigma_t_view;  // the view ray's extinction (OrdersSettings::ss_scaled_view)
  std::vector<std::shared_ptr<const PhaseModel>> phase;  // per component
  std::vector<double> f;                                   // truncated fraction [c*nw+w]
  std::vector<double> cone_deg;                            // truncation cone per component, deg
  std::vector<float> phase_star;                           // [(c*ng+g)*nw+w] on the cos grid
  static constexpr int kPhaseGrid = 2048;
  std::vector<double> albedo, sun_e;

  // Coefficients at altitude z into per-wavelength buffers.
  void SigmaT(double z, bool scaled, float* out) const { SigmaT(m->Locate(z), scaled, out); }
  void SigmaS(size_t c, double z, bool scaled, float* out) const { SigmaS(c, m->Locate(z), scaled, out); }
  void SigmaT(const AtmosphereModel::Cell& cell, bool scaled, float* out) const;
  // The output view ray's extinction: sigma_t_view (the unscaled one unless ss_scaled_view).
  void SigmaTView(const AtmosphereModel::Cell& cell, float* out) const;
  // A per-level table [l * nw + w] interpolated to a cell.
  void LevelLerp(const std::vector<float>& s, const AtmosphereModel::Cell& cell, float* out) const;
  void SigmaS(size_t c, const AtmosphereModel::Cell& cell, bool scaled, float* out) const;
  // sigma_t at one wavelength (the step placement's reference).
  float SigmaTAt(double z, bool scaled, size_t w) const;
  // The truncated phase P*_c(mu) at wavelength w, linear on the cos grid.
  float PhaseStar(size_t c, double mu, size_t w) const;
  // "1 (rayleigh, truncated fraction 0.000 at 570 nm), ...": each scattering component's truncation
  // cone (deg) and the share of its scattering inside it at the grid's middle wavelength.
  std::string ConesText() const;
};

// The medium of model under settings s; ss_scaled_view: the view ray's attenuation delta-scaled
// for the components OrdersSettings::ss_scaled_view selects.
Medium PrepareMedium(const AtmosphereModel& model, const OrdersSettings& s, bool ss_scaled_view);

// The medium at the wavelengths ws (indices into md's, ascending; md.wref among them), each value
// copied, without the phase models (which take the model's wavelength index): a wavelength batch
// of the solve (solve.h).
Medium SliceMedium(const Medium& md, const std::vector<size_t>& ws);

}  // namespace skybake::orders
