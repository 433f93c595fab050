#include "transport/single_scattering.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "atmosphere/ray_sphere.h"
#include "transport/path_tracer.h"

namespace skybake {

namespace {
constexpr double kPi = std::numbers::pi;
// 2-point Gauss-Legendre on [-1, 1]: nodes +-1/sqrt(3), weights 1.
constexpr double kGl2 = 0.5773502691896257;

// Distance to the ground (if hit ahead) and to the top of the atmosphere.
void RayExtent(const AtmosphereModel& m, const glm::dvec3& x, const glm::dvec3& d, double* t_ground, double* t_top) {
  const double b = glm::dot(x, d);
  const double r2 = glm::dot(x, x);
  *t_ground = std::numeric_limits<double>::infinity();
  if (SphereDiscriminantDot(b, r2, m.bottom_radius_m) >= 0.0) {
    const double t0 = DistanceToSphereInDot(b, r2, m.bottom_radius_m);
    if (t0 > 0.0) *t_ground = t0;
  }
  *t_top = ClampDistance(DistanceToSphereOutDot(b, r2, m.top_radius_m));
}
}  // namespace

double OpticalDepth(const AtmosphereModel& m, const glm::dvec3& x, const glm::dvec3& d, double t_max, size_t wl,
                    bool* blocked, double max_piece_m) {
  double t_ground, t_top;
  RayExtent(m, x, d, &t_ground, &t_top);
  *blocked = t_ground < t_max && t_ground <= t_top;
  const double length = std::min({t_max, t_top, t_ground});
  if (!(length > 0.0)) return 0.0;
  const int pieces = std::max(1, static_cast<int>(std::ceil(length / max_piece_m)));
  const double h = length / pieces;
  double tau = 0.0;
  for (int p = 0; p < pieces; ++p) {
    const double c = (p + 0.5) * h;
    for (double s : {-kGl2, kGl2}) {
      const glm::dvec3 y = x + (c + s * 0.5 * h) * d;
      tau += 0.5 * h * m.Extinction(m.Locate(glm::length(y) - m.bottom_radius_m), wl);
    }
  }
  return tau;
}

std::vector<double> SingleScattering(const AtmosphereModel& m, const glm::dvec3& x, const glm::dvec3& d,
                                     const glm::dvec3& sun, const std::vector<size_t>& wl,
                                     const SingleScatteringSettings& s) {
  const size_t k = wl.size();
  std::vector<double> L(k, 0.0);
  double t_ground, t_top;
  RayExtent(m, x, d, &t_ground, &t_top);
  const double length = std::min(t_ground, t_top);
  if (!(length > 0.0)) return L;

  // Sun disk quadrature: directions and weights (solid angle x radiance / irradiance form).
  struct DiskPoint {
    glm::dvec3 w;
    double alpha;
    double weight;  // solid angle of the cell
  };
  std::vector<DiskPoint> disk;
  const SunModel& sm = m.sun;
  if (s.disk_rings <= 0) {
    disk.push_back({sun, 0.0, 0.0});
  } else {
    // Rings uniform in cos(alpha) (equal solid angle), sectors uniform in azimuth.
    const double cos_max = std::cos(sm.angular_radius_rad);
    const double cell = sm.SolidAngle() / (s.disk_rings * s.disk_sectors);
    for (int r = 0; r < s.disk_rings; ++r) {
      const double mu = 1.0 - (r + 0.5) / s.disk_rings * (1.0 - cos_max);
      for (int q = 0; q < s.disk_sectors; ++q) {
        disk.push_back({RotateAround(sun, mu, 2.0 * kPi * (q + 0.5) / s.disk_sectors), std::acos(mu), cell});
      }
    }
  }

  // View-ray quadrature; transmittance from x accumulated piece by piece.
  const int pieces = std::max(1, static_cast<int>(std::ceil(length / s.max_piece_m)));
  const double h = length / pieces;
  std::vector<double> tau(k, 0.0);
  for (int p = 0; p < pieces; ++p) {
    const double c = (p + 0.5) * h;
    for (double g : {-kGl2, kGl2}) {
      const double t = c + g * 0.5 * h;
      const glm::dvec3 y = x + t * d;
      const AtmosphereModel::Cell cell = m.Locate(glm::length(y) - m.bottom_radius_m);
      for (size_t j = 0; j < k; ++j) {
        // Transmittance from x to y: the accumulated depth up to the piece start plus the
        // part of this piece up to y (2-point rule on [start, t], adequate inside one piece).
        const double t0 = p * h;
        double tau_y = tau[j];
        {
          const double hh = t - t0;
          for (double g2 : {-kGl2, kGl2}) {
            const glm::dvec3 z = x + (t0 + (0.5 + 0.5 * g2) * hh) * d;
            tau_y += 0.5 * hh * m.Extinction(m.Locate(glm::length(z) - m.bottom_radius_m), wl[j]);
          }
        }
        double in = 0.0;
        for (const DiskPoint& dp : disk) {
          bool blocked = false;
          const double tau_sun = OpticalDepth(m, y, dp.w, std::numeric_limits<double>::infinity(), wl[j], &blocked,
                                              std::max(s.max_piece_m, 1000.0));
          if (blocked) continue;
          double phase = 0.0, scat = 0.0;
          for (size_t comp = 0; comp < m.components.size(); ++comp) {
            if (!m.components[comp].phase) continue;
            const double sc = m.ComponentScattering(comp, cell, wl[j]);
            scat += sc;
            phase += sc * m.components[comp].phase->Eval(wl[j], glm::dot(d, dp.w));
          }
          const double radiance = s.disk_rings <= 0 ? sm.irradiance[wl[j]] : sm.Radiance(wl[j], dp.alpha) * dp.weight;
          in += phase * radiance * std::exp(-tau_sun);
          (void)scat;
        }
        L[j] += 0.5 * h * std::exp(-tau_y) * in;
      }
    }
    // Advance the accumulated depth by the whole piece.
    for (size_t j = 0; j < k; ++j) {
      for (double g : {-kGl2, kGl2}) {
        const glm::dvec3 z = x + (c + g * 0.5 * h) * d;
        tau[j] += 0.5 * h * m.Extinction(m.Locate(glm::length(z) - m.bottom_radius_m), wl[j]);
      }
    }
  }
  return L;
}

}  // namespace skybake
