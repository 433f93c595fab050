// A finite piece of a view ray, for fog (GT7 "Fog": fog is the in-scattering between the camera
// and the geometry, computed from the low atmosphere only; docs/fog.md).
//
// Definition used by every renderer (path tracer, orders): only medium points on the view ray
// at distance t <= t_end from the observer scatter light toward it, where t_end is the least of
//   - max_distance_m,
//   - where the ray first rises through altitude max_altitude_m (it leaves the "low atmosphere"),
//   - where it reaches the ground.
// The light that illuminates those points is the full atmosphere's (sunlight crosses the whole
// atmosphere to reach them, skylight comes from everywhere): only the view segment is cut.
// The ground surface itself is never part of a segment (the game renders the geometry; fog is
// what lies in front of it). With both limits infinite, segment radiance = sky radiance minus
// the light reflected by the ground surface seen along the ray.
#pragma once

#include <limits>
#include <vector>

#include "atmosphere/model.h"

namespace skybake {

struct ViewSegment {
  double max_distance_m = std::numeric_limits<double>::infinity();
  double max_altitude_m = std::numeric_limits<double>::infinity();
  // false: leave out the single-scattered sunlight (order 1, the sun scattered once toward the
  // observer): GT7's "shadowed fog", the fog inside a cloud's shadow, lit by the sky only.
  bool single_scattering = true;
};

// t_end (m) for an observer at `observer_altitude_m` looking with zenith cosine `mu`. The
// observer must be at or below max_altitude_m (UsageError otherwise). The top of the model's
// atmosphere is a limit too.
double SegmentEnd(const AtmosphereModel& model, double observer_altitude_m, double mu, const ViewSegment& segment);

// Transmittance exp(-int_0^t extinction) along the same ray for every grid wavelength
// (out[w]), by Gauss-Legendre quadrature on the model's levels (exact to < 1e-6 relative for
// the piecewise-linear coefficients of AtmosphereModel).
void SegmentTransmittance(const AtmosphereModel& model, double observer_altitude_m, double mu, double t,
                          std::vector<double>* out);

}  // namespace skybake
