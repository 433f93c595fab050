// The optical depth from a point of the atmosphere to space along a direction, tabulated per
// wavelength over (radius, cosine of the direction's zenith angle): the path tracer's
// segment NEE multiplies its sampling density by exp(-tau) towards the sun, so that in
// twilight the sampled points follow the light that reaches them and not only the medium's
// density (docs/sky-render.md "Deep twilight").
//
// Grid: altitude nodes h_i = H (i / (n_alt - 1))^2 (dense where the air is), and per altitude
// the cosines from the grazing one mu_g(r) = -sqrt(1 - R^2 / r^2) (the ray that touches the
// ground) to 1, uniform in y = sqrt((mu - mu_g) / (1 - mu_g)), so that nodes crowd where tau
// falls steeply with the tangent height. Each node's depth is Simpson's rule on 64 steps of
// each half of the ray either side of its lowest point (the tangent point of a descending ray).
// A direction below mu_g (the ray hits the ground) takes the grazing ray's depth: the sun's disk
// can still be partly seen from there, through about that much air. Depths are capped at
// kMaxDepth (the density's factor e^-30 is never zero, so the density stays positive wherever
// the sun may be seen, and the estimator unbiased). Bilinear in (altitude index, y).
#pragma once

#include <cstddef>
#include <vector>

#include "atmosphere/model.h"

namespace skybake {

class SunDepthTable {
 public:
  static constexpr double kMaxDepth = 30.0;

  explicit SunDepthTable(const AtmosphereModel& model, int altitudes = 48, int cosines = 128, int steps = 64);

  // Optical depth (dimensionless) at radius r (m, planet-centred) towards a direction of cosine
  // mu with the local vertical, for grid wavelength w.
  double Depth(double r, double mu, size_t w) const;
  // The same for the k grid wavelengths w[0..k) at once (the interpolation weights found once).
  void Depths(double r, double mu, const size_t* w, int k, double* out) const;

 private:
  double bottom_, top_;
  int na_, nm_;
  size_t nw_;
  std::vector<double> radius_;  // n_alt node radii (m)
  std::vector<float> depth_;    // [(i * nm + j) * nw + w]
};

}  // namespace skybake
