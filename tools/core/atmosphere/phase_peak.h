// A scattering component's phase peak, and the peak above which the transport methods treat a
// component as a cloud's diffraction peak: the path tracer's cloud estimators (docs/sky-render.md
// "Clouds") and the droplets' truncation cone of `orders` (docs/sky-methods.md "Truncation cone
// per component").
#pragma once

#include <algorithm>
#include <cstddef>

#include "atmosphere/model.h"

namespace skybake {

// sr^-1: cloud droplets peak at ~1e3, the aerosols near 10, air at 0.12.
inline constexpr double kPeakedPhaseMin = 30.0;

// The largest value of a phase function over the first nw wavelengths, forward or backward (sr^-1;
// every phase model here peaks at one of the two).
inline double PhasePeak(const PhaseModel& phase, size_t nw) {
  double peak = 0.0;
  for (size_t w = 0; w < nw; ++w) peak = std::max({peak, phase.Eval(w, 1.0), phase.Eval(w, -1.0)});
  return peak;
}

}  // namespace skybake
