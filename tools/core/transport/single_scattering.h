// Deterministic single scattering by quadrature along the view ray (the `single` method of
// sky-render, and the independent check of the path tracer's first order).
//
//   L_1(x, d) = int_0^{t_end} T(x, x_t) sum_c sigma_s,c(x_t) int_disk P_c(d . w) L_sun(w) T(x_t -> space along w) dw dt
//   (Bruneton & Neyret 2008 eq. 4 with the sun as an extended, limb-darkened disk)
// - the view ray ends at the ground or the top of the atmosphere;
// - optical depths are integrated by composite 2-point Gauss-Legendre on pieces of at most
//   `max_piece_m` (the coefficients are linear between levels, so the error is that of the
//   rule on a smooth integrand: < 1e-6 relative with 100 m pieces);
// - the sun disk is integrated with `disk_rings` x `disk_sectors` points (midpoint in the
//   projected radius and azimuth), or as a point of irradiance E_0 when disk_rings = 0;
// - a disk point hidden by the planet contributes nothing (Earth's shadow, penumbra included).
#pragma once

#include <glm/vec3.hpp>

#include <vector>

#include "atmosphere/model.h"

namespace skybake {

// Optical depth from x along unit d over a distance t_max (infinity: to the top of the
// atmosphere), for wavelength wl. Sets *blocked when the ray hits the ground first (the
// returned depth then stops there).
double OpticalDepth(const AtmosphereModel& model, const glm::dvec3& x, const glm::dvec3& d, double t_max, size_t wl,
                    bool* blocked, double max_piece_m = 100.0);

struct SingleScatteringSettings {
  double max_piece_m = 100.0;   // view-ray quadrature pieces
  int disk_rings = 3;           // 0: point sun
  int disk_sectors = 8;
};

// Spectral single-scattered radiance (W m^-2 sr^-1 nm^-1) for the wavelengths `wl`.
std::vector<double> SingleScattering(const AtmosphereModel& model, const glm::dvec3& x, const glm::dvec3& d,
                                     const glm::dvec3& sun, const std::vector<size_t>& wl,
                                     const SingleScatteringSettings& settings);

}  // namespace skybake
