// The sun transmittance of `orders`, averaged over the limb-darkened solar disk (which gives the
// Earth's shadow its penumbra): T(r, theta_s) per wavelength for the true medium (the exact single
// scattering and the ground's direct sun at the output) and for the delta-scaled one (the sources
// of the multiple-scattering tables); docs/sky-methods.md "Sun transmittance".
#pragma once

#include <cstdint>
#include <vector>

#include "transport/orders/grid.h"
#include "transport/orders/medium.h"

namespace skybake::orders {

// Radius nodes x theta nodes x nw, and the logarithms (0 where the transmittance is 0) with a
// per-node flag "every wavelength lit" and the grid's shortest wavelength's transmittance (which
// decides the blend: TransmittanceAt), both of the whole grid in a wavelength batch's slice too.
struct SunTable {
  std::vector<double> r;
  IntervalLocator loc;
  std::vector<float> t, lt;
  std::vector<uint8_t> pos;
  std::vector<float> first;
};

struct SunTables {
  SunTable plain, star;  // unscaled, delta-scaled
  std::vector<double> theta_deg;
  IntervalLocator theta_loc;
  size_t nw = 0;

  // Disk-averaged sun transmittance at radius r and sun zenith cosine mu_s into out[w].
  void Transmittance(double r, double mu_s, bool scaled, float* out) const { TransmittanceAt(Radius(r, scaled), mu_s, scaled, out); }
  // The same with the radius part of the lookup done once (a view ray's point, every direction).
  Lerp Radius(double r, bool scaled) const { return Locate((scaled ? star : plain).loc, r); }
  void TransmittanceAt(const Lerp& lr, double mu_s, bool scaled, float* out) const;
};

SunTables BuildSunTables(const AtmosphereModel& m, const Medium& md, const OrdersSettings& s);

// The tables at the wavelengths ws (indices into sun's, ascending): a wavelength batch of the
// solve, whose lookups give the same values as the whole tables' at those wavelengths.
SunTables SliceSunTables(const SunTables& sun, const std::vector<size_t>& ws);

}  // namespace skybake::orders
