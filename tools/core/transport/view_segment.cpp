#include "transport/view_segment.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "atmosphere/ray_sphere.h"
#include "io/error.h"

namespace skybake {

double SegmentEnd(const AtmosphereModel& model, double observer_altitude_m, double mu, const ViewSegment& segment) {
  const double R = model.bottom_radius_m;
  const double cut = std::min(segment.max_altitude_m, model.top_radius_m - R);
  if (observer_altitude_m > cut + 1e-6) {
    throw UsageError(fmt::format("the observer ({} m) is above the segment's altitude limit ({} m)",
                                 observer_altitude_m, cut));
  }
  if (!(segment.max_distance_m >= 0.0)) throw UsageError("a view segment's distance must be >= 0");
  const double r = R + std::max(0.0, observer_altitude_m);
  mu = std::clamp(mu, -1.0, 1.0);
  double t = DistanceToSphereOut(r, mu, R + cut);
  if (RayIntersectsGround(r, mu, R)) t = std::min(t, DistanceToSphereIn(r, mu, R));
  return std::max(0.0, std::min(t, segment.max_distance_m));
}

void SegmentTransmittance(const AtmosphereModel& model, double observer_altitude_m, double mu, double t,
                          std::vector<double>* out) {
  const size_t nw = model.wavelengths();
  out->assign(nw, 0.0);
  if (!(t > 0.0)) {
    std::fill(out->begin(), out->end(), 1.0);
    return;
  }
  const double R = model.bottom_radius_m;
  const double r = R + std::max(0.0, observer_altitude_m);
  auto altitude = [&](double s) { return RadiusAt(r, mu, s) - R; };
  // Pieces: the altitude changes by at most 50 m + 5 % of the altitude across one, and none is
  // longer than 20 km; 4-point Gauss-Legendre on each.
  static const double kX[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double kW[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double s0 = 0.0;
  for (int guard = 0; s0 < t; ++guard) {
    if (guard > 1000000) throw InternalError("SegmentTransmittance did not terminate");
    const double z = std::max(0.0, altitude(s0));
    const double dz_max = 50.0 + 0.05 * z;
    // Local slope of the altitude, |dz/ds| <= 1; curvature adds at most s^2 / (2 R).
    const double rr = R + z;
    const double slope = std::abs(MuAt(r, mu, s0, rr));
    double h = std::min(20e3, t - s0);
    if (slope * h > dz_max) h = dz_max / slope;
    h = std::max(h, std::min(1.0, t - s0));
    for (int q = 0; q < 4; ++q) {
      const double s = s0 + 0.5 * h * (1.0 + kX[q]);
      const AtmosphereModel::Cell cell = model.Locate(std::max(0.0, altitude(s)));
      for (size_t w = 0; w < nw; ++w) (*out)[w] += 0.5 * h * kW[q] * model.Extinction(cell, w);
    }
    s0 += h;
  }
  for (size_t w = 0; w < nw; ++w) (*out)[w] = std::exp(-(*out)[w]);
}

}  // namespace skybake
