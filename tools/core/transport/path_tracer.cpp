#include "transport/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "atmosphere/ray_sphere.h"
#include "io/error.h"
#include "transport/running_moments.h"

namespace skybake {
namespace {

constexpr double kPi = std::numbers::pi;

// Target shell thickness (m) by altitude: thin where the aerosol and the air are dense, thick
// above. Only efficiency depends on this (majorants are exact for any shells).
double ShellThickness(double altitude_m) {
  if (altitude_m < 2000.0) return 250.0;
  if (altitude_m < 6000.0) return 500.0;
  if (altitude_m < 20000.0) return 1000.0;
  if (altitude_m < 50000.0) return 2500.0;
  return 5000.0;
}

// Distance along the unit direction d from p to the sphere of radius R: the exit (far) root
// when inside, the entry (near) root otherwise; -1 when there is no intersection ahead.
struct SphereHit {
  double t;
  bool hit;
};

SphereHit NearSphere(const glm::dvec3& p, const glm::dvec3& d, double radius) {
  const double b = glm::dot(p, d), r2 = glm::dot(p, p);
  if (SphereDiscriminantDot(b, r2, radius) < 0.0) return {0.0, false};
  const double t0 = DistanceToSphereInDot(b, r2, radius);
  if (t0 > 0.0) return {t0, true};
  return {0.0, false};
}

double FarSphere(const glm::dvec3& p, const glm::dvec3& d, double radius) {
  return DistanceToSphereOutDot(glm::dot(p, d), glm::dot(p, p), radius);
}

// Largest majorant scale of segment NEE's transmittances (TransmittanceAlong): relative
// variance e^(tau / c) - 1 stays below e - 1 up to tau = 8.
constexpr double kMaxMajorantScale = 8.0;

// The twilight guide's band (PathTracerSettings::twilight_guide): sin(elevation) in
// [kBandSinLo, kBandSinHi] above the local horizontal, azimuth within kBandAzimuth of the
// sun's; uniform in solid angle.
constexpr double kBandSinLo = -0.1, kBandSinHi = 0.35, kBandAzimuth = kPi / 3.0;
constexpr double kBandSolidAngle = (kBandSinHi - kBandSinLo) * 2.0 * kBandAzimuth;

// The band's frame at x: up n, towards the sun's azimuth g, and b = n x g; false where the sun
// is (nearly) straight above or below, so that no azimuth is the sun's.
bool BandFrame(const glm::dvec3& x, const glm::dvec3& sun, glm::dvec3* n, glm::dvec3* g, glm::dvec3* b) {
  *n = glm::normalize(x);
  const glm::dvec3 h = sun - glm::dot(sun, *n) * *n;
  const double len = glm::length(h);
  if (len < 1e-6) return false;
  *g = h / len;
  *b = glm::cross(*n, *g);
  return true;
}

double BandPdf(const glm::dvec3& d, const glm::dvec3& n, const glm::dvec3& g, const glm::dvec3& b) {
  const double se = glm::dot(d, n);
  if (se < kBandSinLo || se > kBandSinHi) return 0.0;
  const double a = std::atan2(glm::dot(d, b), glm::dot(d, g));
  return std::abs(a) <= kBandAzimuth ? 1.0 / kBandSolidAngle : 0.0;
}

glm::dvec3 SampleBand(const glm::dvec3& n, const glm::dvec3& g, const glm::dvec3& b, double u1, double u2) {
  const double se = kBandSinLo + u1 * (kBandSinHi - kBandSinLo);
  const double ce = std::sqrt(std::max(0.0, 1.0 - se * se));
  const double a = (2.0 * u2 - 1.0) * kBandAzimuth;
  return glm::normalize(ce * (std::cos(a) * g + std::sin(a) * b) + se * n);
}

glm::dvec3 CosineHemisphere(const glm::dvec3& n, double u1, double u2) {
  // Malley's method: uniform disk sample projected up (pdf = cos / pi).
  const double mu = std::sqrt(std::max(0.0, 1.0 - u1));
  return RotateAround(n, mu, 2.0 * kPi * u2);
}

}  // namespace

glm::dvec3 DirectionFromAngles(double zenith, double azimuth) {
  return {std::sin(zenith) * std::cos(azimuth), std::sin(zenith) * std::sin(azimuth), std::cos(zenith)};
}

glm::dvec3 RotateAround(const glm::dvec3& axis, double mu, double phi) {
  // Frisvad-style branchless basis (Duff et al. 2017, "Building an orthonormal basis, revisited").
  const double sign = std::copysign(1.0, axis.z);
  const double a = -1.0 / (sign + axis.z);
  const double b = axis.x * axis.y * a;
  const glm::dvec3 t(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
  const glm::dvec3 bt(b, sign + axis.y * axis.y * a, -axis.y);
  const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  return glm::normalize(mu * axis + s * (std::cos(phi) * t + std::sin(phi) * bt));
}

PathTracer::PathTracer(const AtmosphereModel& model, std::vector<std::array<double, 3>> xyz_weights,
                       PathTracerSettings settings)
    : model_(model), xyz_weights_(std::move(xyz_weights)), settings_(settings) {
  SKYBAKE_CHECK_EQ(xyz_weights_.size(), model_.wavelengths());
  SKYBAKE_CHECK(settings_.wavelengths_per_path >= 1 && settings_.wavelengths_per_path <= kMaxWavelengths);
  // Shells: runs of levels whose thickness reaches ShellThickness.
  const std::vector<double>& z = model_.altitude_m;
  size_t lo = 0;
  while (lo + 1 < z.size()) {
    size_t hi = lo + 1;
    while (hi + 1 < z.size() && z[hi] - z[lo] < ShellThickness(z[lo])) ++hi;
    shells_.push_back({lo, hi, model_.bottom_radius_m + z[lo], model_.bottom_radius_m + z[hi]});
    lo = hi;
  }
  shells_.back().radius_hi = model_.top_radius_m;
  const size_t nw = model_.wavelengths();
  shell_majorant_.resize(shells_.size() * nw);
  for (size_t s = 0; s < shells_.size(); ++s) {
    for (size_t w = 0; w < nw; ++w) shell_majorant_[s * nw + w] = model_.MaxExtinction(shells_[s].level_lo, shells_[s].level_hi, w);
  }
  // P_max (sr^-1) of each scattering component (every phase model here peaks forward or
  // backward) and of them all.
  const size_t nc = model_.components.size();
  std::vector<double> component_peak(nc, 0.0);
  for (size_t c = 0; c < nc; ++c) {
    const MediumComponent& comp = model_.components[c];
    if (!comp.phase || *std::max_element(comp.scattering.begin(), comp.scattering.end()) <= 0.0) continue;
    component_peak[c] = PhasePeak(*comp.phase, nw);
  }
  const double peak = *std::max_element(component_peak.begin(), component_peak.end());
  // The sun-peak guide's mixture: the components whose peak exceeds sun_peak_min, each by its
  // share of their column scattering optical depth (trapezoid over the levels) per wavelength.
  // Without such a component the guide is off.
  peak_guide_ = settings_.sun_peak_guide;
  peak_weight_.assign(nw * nc, 0.0);
  for (size_t w = 0; w < nw; ++w) {
    double sum = 0.0;
    for (size_t c = 0; c < nc; ++c) {
      const MediumComponent& comp = model_.components[c];
      if (component_peak[c] <= settings_.sun_peak_min) continue;
      double tau = 0.0;
      for (size_t l = 0; l + 1 < model_.levels(); ++l) {
        tau += 0.5 * (comp.scattering[l * nw + w] + comp.scattering[(l + 1) * nw + w]) * (z[l + 1] - z[l]);
      }
      peak_weight_[w * nc + c] = tau;
      sum += tau;
    }
    for (size_t c = 0; c < nc; ++c) peak_weight_[w * nc + c] = sum > 0.0 ? peak_weight_[w * nc + c] / sum : 0.0;
    // A wavelength on which the peaked components do not scatter at all leaves the guide off.
    if (!(sum > 0.0)) peak_guide_ = 0.0;
  }
  cloud_estimators_ = peak > settings_.sun_peak_min && settings_.illumination == Illumination::kSun;
  if (!cloud_estimators_) peak_guide_ = 0.0;
  shadow_radius_m_ = model_.bottom_radius_m -
                     (model_.sun.angular_radius_rad * DistanceToHorizon(model_.top_radius_m, model_.bottom_radius_m) + 1.0);
  double min_paths = std::ceil(settings_.rare_peak_events * 4.0 * kPi * peak);
  if (peak_guide_ > 0.0) min_paths = std::min(min_paths, static_cast<double>(settings_.guided_peak_paths));
  split_above_ = cloud_estimators_ ? settings_.split_above : 0.0;
  peak_min_paths_ = min_paths >= static_cast<double>(settings_.max_paths) ? settings_.max_paths : static_cast<uint64_t>(min_paths);
}

bool PathTracer::InEarthShadow(const glm::dvec3& x, const glm::dvec3& sun) const {
  const double xs = glm::dot(x, sun);
  return xs < 0.0 && glm::dot(x, x) - xs * xs < shadow_radius_m_ * shadow_radius_m_;
}

size_t PathTracer::ShellOf(double radius) const {
  auto it = std::upper_bound(shells_.begin(), shells_.end(), radius,
                             [](double r, const Shell& s) { return r < s.radius_lo; });
  size_t s = it == shells_.begin() ? 0 : static_cast<size_t>(it - shells_.begin()) - 1;
  return std::min(s, shells_.size() - 1);
}

double PathTracer::Majorant(size_t shell, const size_t* idx, int k) const {
  const size_t nw = model_.wavelengths();
  double m = 0.0;
  for (int j = 0; j < k; ++j) m = std::max(m, shell_majorant_[shell * nw + idx[j]]);
  return m;
}

double PathTracer::MixturePhase(const AtmosphereModel::Cell& cell, size_t wl, double mu) const {
  double num = 0.0, den = 0.0;
  for (size_t c = 0; c < model_.components.size(); ++c) {
    if (!model_.components[c].phase) continue;
    const double s = model_.ComponentScattering(c, cell, wl);
    if (s <= 0.0) continue;
    num += s * model_.components[c].phase->Eval(wl, mu);
    den += s;
  }
  return den > 0.0 ? num / den : 0.0;
}

glm::dvec3 PathTracer::SamplePeakAboutSun(size_t wl, const glm::dvec3& sun, Pcg32& rng) const {
  const size_t nc = model_.components.size();
  double u = rng.Uniform();
  size_t chosen = nc;
  for (size_t c = 0; c < nc; ++c) {
    const double w = peak_weight_[wl * nc + c];
    if (w <= 0.0) continue;
    chosen = c;
    if (u < w) break;
    u -= w;
  }
  SKYBAKE_CHECK_LT(chosen, nc);
  return RotateAround(sun, model_.components[chosen].phase->SampleMu(wl, rng.Uniform()), 2.0 * kPi * rng.Uniform());
}

double PathTracer::PeakAboutSunPdf(const size_t* idx, int nh, double cos_to_sun) const {
  const size_t nc = model_.components.size();
  const double mu = std::clamp(cos_to_sun, -1.0, 1.0);
  double pdf = 0.0;
  for (int h = 0; h < nh; ++h) {
    for (size_t c = 0; c < nc; ++c) {
      const double w = peak_weight_[idx[h] * nc + c];
      if (w > 0.0) pdf += w * model_.components[c].phase->Eval(idx[h], mu);
    }
  }
  return pdf / nh;
}

void PathTracer::Transmittance(const glm::dvec3& position, const glm::dvec3& direction, const size_t* idx, int k,
                               Pcg32& rng, double* T) const {
  TransmittanceAlong(position, direction, std::numeric_limits<double>::infinity(), idx, k, rng, T);
}

void PathTracer::TransmittanceAlong(const glm::dvec3& position, const glm::dvec3& direction, double t_max,
                                    const size_t* idx, int k, Pcg32& rng, double* T, double roulette_below,
                                    double majorant_scale) const {
  for (int j = 0; j < k; ++j) T[j] = 1.0;
  double travelled = 0.0;
  glm::dvec3 p = position;
  size_t s = ShellOf(glm::length(p));
  for (int guard = 0; guard < 100000; ++guard) {
    const Shell& sh = shells_[s];
    // Where the ray leaves this shell: through the inner sphere (if it goes down and hits it)
    // or through the outer one.
    SphereHit inner = NearSphere(p, direction, sh.radius_lo);
    const bool down = inner.hit;
    double t_exit = down ? inner.t : FarSphere(p, direction, sh.radius_hi);
    const bool last = travelled + t_exit >= t_max;
    if (last) t_exit = t_max - travelled;
    const double mu_bar = majorant_scale * Majorant(s, idx, k);
    double t = 0.0;
    if (mu_bar > 0.0) {
      for (;;) {
        t -= std::log(1.0 - rng.Uniform()) / mu_bar;
        if (t >= t_exit) break;
        const glm::dvec3 x = p + t * direction;
        const AtmosphereModel::Cell cell = model_.Locate(glm::length(x) - model_.bottom_radius_m);
        double tmax = 0.0;
        for (int j = 0; j < k; ++j) {
          T[j] *= std::max(0.0, 1.0 - model_.Extinction(cell, idx[j]) / mu_bar);
          tmax = std::max(tmax, T[j]);
        }
        // Russian roulette on tiny transmittances (unbiased: survivors are reweighted).
        if (tmax < roulette_below) {
          const double q = tmax / roulette_below;
          if (rng.Uniform() >= q) {
            for (int j = 0; j < k; ++j) T[j] = 0.0;
            return;
          }
          for (int j = 0; j < k; ++j) T[j] /= q;
        }
      }
    }
    if (last) return;
    p += t_exit * direction;
    travelled += t_exit;
    if (down) {
      if (s == 0) {  // the ground: the sun is hidden
        for (int j = 0; j < k; ++j) T[j] = 0.0;
        return;
      }
      --s;
    } else {
      if (s + 1 == shells_.size()) return;  // left the atmosphere
      ++s;
    }
  }
  throw InternalError("transmittance traversal did not terminate");
}

void PathTracer::SunNee(const glm::dvec3& x, const glm::dvec3& d, bool ground, const double* beta, const size_t* idx,
                        int k, const glm::dvec3& sun, Pcg32& rng, double* L) const {
  const SunModel& sm = model_.sun;
  // Uniform direction in the disk's cone: pdf = 1 / Omega.
  const double cos_max = std::cos(sm.angular_radius_rad);
  const double mu_c = 1.0 - rng.Uniform() * (1.0 - cos_max);
  const glm::dvec3 wl = RotateAround(sun, mu_c, 2.0 * kPi * rng.Uniform());
  const double alpha = std::acos(std::clamp(mu_c, -1.0, 1.0));
  const glm::dvec3 up = glm::normalize(x);
  double geom[kMaxWavelengths];
  if (ground) {
    const double cos_l = glm::dot(up, wl);
    if (cos_l <= 0.0) return;
    for (int j = 0; j < k; ++j) geom[j] = model_.ground_albedo[idx[j]] / kPi * cos_l;
  } else {
    const AtmosphereModel::Cell cell = model_.Locate(glm::length(x) - model_.bottom_radius_m);
    const double mu = glm::dot(d, wl);
    for (int j = 0; j < k; ++j) geom[j] = MixturePhase(cell, idx[j], mu);
  }
  bool any = false;
  for (int j = 0; j < k; ++j) any = any || (beta[j] * geom[j] != 0.0);
  if (!any) return;
  double T[kMaxWavelengths];
  // Start the shadow ray a hair above the ground so that it does not re-hit it.
  const glm::dvec3 origin = ground ? x + up * 1e-3 : x;
  Transmittance(origin, wl, idx, k, rng, T);
  const double omega = sm.SolidAngle();
  for (int j = 0; j < k; ++j) L[j] += beta[j] * geom[j] * T[j] * sm.Radiance(idx[j], alpha) * omega;
}


void PathTracer::SegmentSunNee(const glm::dvec3& p, const glm::dvec3& d, const double* beta, const size_t* idx, int k,
                               const glm::dvec3& sun, Pcg32& rng, double* L, double t_cap, double nee_floor_y) const {
  const double R = model_.bottom_radius_m, top = model_.top_radius_m;
  const SphereHit g = NearSphere(p, d, R);
  const double t_end = std::min(t_cap, g.hit ? g.t : FarSphere(p, d, top));
  if (!(t_end > 0.0)) return;
  // Lit set along x(t) = p + t d: the points outside the umbra (InEarthShadow).
  const double rs = shadow_radius_m_;
  const double ps = glm::dot(p, sun), ds = glm::dot(d, sun);
  auto lit = [&](double t) { return !InEarthShadow(p + t * d, sun); };
  double bp[6];
  int nb = 0;
  bp[nb++] = 0.0;
  if (std::abs(ds) > 1e-15) {
    const double t0 = -ps / ds;
    if (t0 > 0.0 && t0 < t_end) bp[nb++] = t0;
  }
  {
    const double a = 1.0 - ds * ds;
    const double b = 2.0 * (glm::dot(p, d) - ps * ds);
    const double c = glm::dot(p, p) - ps * ps - rs * rs;
    if (a > 1e-15) {
      const double disc = b * b - 4.0 * a * c;
      if (disc > 0.0) {
        const double sq = std::sqrt(disc);
        for (double t : {(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)}) {
          if (t > 0.0 && t < t_end) bp[nb++] = t;
        }
      }
    }
  }
  bp[nb++] = t_end;
  std::sort(bp, bp + nb);
  // Lit intervals and their total length.
  double lit_lo[5], lit_hi[5];
  int nl = 0;
  double lit_len = 0.0;
  for (int i = 0; i + 1 < nb; ++i) {
    if (bp[i + 1] - bp[i] <= 0.0) continue;
    if (lit(0.5 * (bp[i] + bp[i + 1]))) {
      if (nl > 0 && lit_hi[nl - 1] == bp[i]) {
        lit_hi[nl - 1] = bp[i + 1];
      } else {
        lit_lo[nl] = bp[i];
        lit_hi[nl] = bp[i + 1];
        ++nl;
      }
      lit_len += bp[i + 1] - bp[i];
    }
  }
  if (nl == 0) return;
  // Pieces over the lit part. A technique wavelength's weight W(t) = scattering x attenuation
  // along the segment (trapezoid rule) x (sun_guided_nee) the tabulated attenuation towards the
  // sun of the least attenuated carried wavelength is evaluated at the pieces' ends and taken log-linear within each piece (uniform where
  // an end has none): a density that is exactly known and follows the exponential fall of W
  // along a grazing ray, where a constant per piece leaves rare points with large weights. One
  // technique (the hero idx[0]), or with wavelength_mis one per carried wavelength, the piece
  // drawn from a uniformly chosen one and the density the techniques' mixture (one-sample MIS).
  constexpr int kPieces = 64;
  const int nh = settings_.wavelength_mis ? k : 1;
  const SunDepthTable* sun_depth = settings_.sun_guided_nee ? &SunDepth() : nullptr;
  double piece_lo[kPieces + 5], piece_len[kPieces + 5];
  double piece_w0[kMaxWavelengths][kPieces + 5], piece_w1[kMaxWavelengths][kPieces + 5];
  double piece_mass[kMaxWavelengths][kPieces + 5];
  double piece_tau[kMaxWavelengths][kPieces + 5];  // view optical depth at the piece's start
  double total[kMaxWavelengths], tau[kMaxWavelengths];
  for (int h = 0; h < nh; ++h) total[h] = tau[h] = 0.0;
  // W at t (and the extinction there, for the trapezoid rule) for every technique.
  double w_at[kMaxWavelengths], ext_at[kMaxWavelengths];
  auto weights_at = [&](double t) {
    const glm::dvec3 x = p + t * d;
    const double rx = glm::length(x);
    const AtmosphereModel::Cell cell = model_.Locate(rx - R);
    const double mu_sun = glm::dot(x, sun) / rx;
    // The sun factor: the least attenuated carried wavelength's, so that no carried wavelength
    // is sampled below its own light (a 680 nm sun ray through the lower atmosphere keeps light
    // that a 420 nm one has lost: with the hero's factor its points would be rare and heavy).
    double sun_factor = 1.0;
    if (sun_depth) {
      double tau_min = SunDepthTable::kMaxDepth;
      double depths[kMaxWavelengths];
      sun_depth->Depths(rx, mu_sun, idx, k, depths);
      for (int j = 0; j < k; ++j) tau_min = std::min(tau_min, depths[j]);
      sun_factor = std::exp(-tau_min);
    }
    for (int hh = 0; hh < nh; ++hh) {
      ext_at[hh] = model_.Extinction(cell, idx[hh]);
      w_at[hh] = model_.Scattering(cell, idx[hh]) * std::exp(-tau[hh]) * sun_factor;
    }
  };
  int np = 0;
  double t_prev = 0.0;
  for (int i = 0; i < nl; ++i) {
    // Attenuation across the shadowed gap before this interval (4-point midpoint rule).
    if (lit_lo[i] > t_prev) {
      const double h = (lit_lo[i] - t_prev) / 4.0;
      for (int q = 0; q < 4; ++q) {
        const glm::dvec3 x = p + (t_prev + (q + 0.5) * h) * d;
        const AtmosphereModel::Cell cell = model_.Locate(glm::length(x) - R);
        for (int hh = 0; hh < nh; ++hh) tau[hh] += model_.Extinction(cell, idx[hh]) * h;
      }
    }
    const int n = std::max(1, static_cast<int>(std::round(kPieces * (lit_hi[i] - lit_lo[i]) / lit_len)));
    const double h = (lit_hi[i] - lit_lo[i]) / n;
    weights_at(lit_lo[i]);
    for (int q = 0; q < n && np < kPieces + 5; ++q) {
      double w0[kMaxWavelengths], e0[kMaxWavelengths];
      for (int hh = 0; hh < nh; ++hh) {
        w0[hh] = w_at[hh];
        e0[hh] = ext_at[hh];
        piece_tau[hh][np] = tau[hh];
      }
      // The end's W needs the depth there, which needs the end's extinction: the trapezoid
      // step takes the end's extinction from a first evaluation at the start's depth.
      const double t1 = lit_lo[i] + (q + 1) * h;
      weights_at(t1);
      for (int hh = 0; hh < nh; ++hh) {
        const double dtau = 0.5 * (e0[hh] + ext_at[hh]) * h;
        tau[hh] += dtau;
        w_at[hh] *= std::exp(-dtau);
        piece_w0[hh][np] = w0[hh];
        piece_w1[hh][np] = w_at[hh];
        const double a = w0[hh], b = w_at[hh];
        double mass;
        if (a > 0.0 && b > 0.0) {
          const double slope = std::log(b / a);
          mass = std::abs(slope) > 1e-9 ? h * (b - a) / slope : h * a;
        } else {
          mass = 0.5 * (a + b) * h;
        }
        piece_mass[hh][np] = mass;
        total[hh] += mass;
      }
      piece_lo[np] = lit_lo[i] + q * h;
      piece_len[np] = h;
      ++np;
    }
    t_prev = lit_hi[i];
  }
  // The techniques that can sample (a wavelength that does not scatter anywhere here cannot).
  int usable[kMaxWavelengths];
  int nu = 0;
  for (int hh = 0; hh < nh; ++hh) {
    if (total[hh] > 0.0) usable[nu++] = hh;
  }
  if (nu == 0) return;
  int tech = usable[0];
  if (nh > 1) tech = usable[std::min(nu - 1, static_cast<int>(rng.Uniform() * nu))];
  double u = rng.Uniform() * total[tech];
  int chosen = np - 1;
  for (int i = 0; i < np; ++i) {
    if (u < piece_mass[tech][i]) {
      chosen = i;
      break;
    }
    u -= piece_mass[tech][i];
  }
  if (piece_mass[tech][chosen] <= 0.0) return;
  // Density within the piece of technique hh at fraction f of it (per metre, normalised over
  // the segment), and the inverse of the chosen technique's distribution within the piece.
  auto log_linear = [&](int hh) {
    const double a = piece_w0[hh][chosen], b = piece_w1[hh][chosen];
    return a > 0.0 && b > 0.0 ? std::log(b / a) : std::numeric_limits<double>::quiet_NaN();
  };
  auto density = [&](int hh, double f) {
    const double slope = log_linear(hh);
    if (std::isnan(slope)) return piece_mass[hh][chosen] / (piece_len[chosen] * total[hh]);
    return piece_w0[hh][chosen] * std::exp(slope * f) / total[hh];
  };
  const double u2 = rng.Uniform();
  double frac = u2;
  {
    const double slope = log_linear(tech);
    if (!std::isnan(slope) && std::abs(slope) > 1e-9) frac = std::clamp(std::log1p(u2 * std::expm1(slope)) / slope, 0.0, 1.0);
  }
  const double t_star = piece_lo[chosen] + frac * piece_len[chosen];
  double pdf = 0.0;
  for (int q = 0; q < nu; ++q) pdf += density(usable[q], frac);
  pdf /= nu;
  if (!(pdf > 0.0)) return;
  const glm::dvec3 x = p + t_star * d;
  const AtmosphereModel::Cell cell = model_.Locate(glm::length(x) - R);
  // Sun direction in the disk's cone.
  const SunModel& sm = model_.sun;
  const double cos_max = std::cos(sm.angular_radius_rad);
  const double mu_c = 1.0 - rng.Uniform() * (1.0 - cos_max);
  const glm::dvec3 wl = RotateAround(sun, mu_c, 2.0 * kPi * rng.Uniform());
  const double alpha = std::acos(std::clamp(mu_c, -1.0, 1.0));
  const double mu = glm::dot(d, wl);
  double f[kMaxWavelengths];
  bool any = false;
  for (int j = 0; j < k; ++j) {
    f[j] = beta[j] * model_.Scattering(cell, idx[j]) * MixturePhase(cell, idx[j], mu);
    any = any || f[j] != 0.0;
  }
  if (!any) return;
  // The transmittances follow the optical depths the wavelengths are expected to see (the
  // pieces' view depth of the techniques, the tabulated sun depth of the carried ones): the
  // roulette starts 1e-3 below the least attenuated one's expectation (it acts on the largest
  // T), the majorant scale is the largest depth (kMaxMajorantScale at most).
  double view_min = INFINITY, view_max = 0.0, sun_min = INFINITY, sun_max = 0.0;
  for (int q = 0; q < nu; ++q) {
    view_min = std::min(view_min, piece_tau[usable[q]][chosen]);  // at the piece's start
    view_max = std::max(view_max, piece_tau[usable[q]][chosen]);
  }
  if (sun_depth) {
    const double rx = glm::length(x), mu_sun = glm::dot(x, sun) / rx;
    double depths[kMaxWavelengths];
    sun_depth->Depths(rx, mu_sun, idx, k, depths);
    for (int j = 0; j < k; ++j) {
      const double t = depths[j];
      sun_min = std::min(sun_min, t);
      sun_max = std::max(sun_max, t);
    }
  } else {
    sun_min = 0.0;
  }
  const double omega = sm.SolidAngle();
  // Russian roulette on a connection whose expected Y (the transmittances taken as the expected
  // depths' e^-tau) is below nee_floor_y: survivors are divided by the survival probability.
  if (nee_floor_y > 0.0) {
    double expected = 0.0;
    for (int j = 0; j < k; ++j) expected += xyz_weights_[idx[j]][1] * f[j] * sm.Radiance(idx[j], alpha);
    expected *= omega / pdf * std::exp(-(view_min + sun_min)) * static_cast<double>(model_.wavelengths()) / k;
    if (expected < nee_floor_y) {
      const double q = expected / nee_floor_y;
      if (!(q > 0.0) || rng.Uniform() >= q) return;
      for (int j = 0; j < k; ++j) f[j] /= q;
    }
  }
  double t_view[kMaxWavelengths], t_sun[kMaxWavelengths];
  TransmittanceAlong(p, d, t_star, idx, k, rng, t_view, 1e-3 * std::exp(-view_min), std::clamp(view_max, 1.0, kMaxMajorantScale));
  TransmittanceAlong(x, wl, std::numeric_limits<double>::infinity(), idx, k, rng, t_sun, 1e-3 * std::exp(-sun_min),
                     std::clamp(sun_max, 1.0, kMaxMajorantScale));
  for (int j = 0; j < k; ++j) L[j] += f[j] * t_view[j] * t_sun[j] * sm.Radiance(idx[j], alpha) * omega / pdf;
}

const SunDepthTable& PathTracer::SunDepth() const {
  std::call_once(sun_depth_once_, [this] { sun_depth_ = std::make_unique<SunDepthTable>(model_); });
  return *sun_depth_;
}

namespace {
// Copies the radiance gathered so far into L1 once: when the path reaches its first scattering
// or reflection event (every later sun connection is of order >= 2) or ends before it.
struct FirstOrderCapture {
  double* L1;
  const double* L;
  int k;
  bool done = false;
  void Take() {
    if (L1 == nullptr || done) return;
    for (int j = 0; j < k; ++j) L1[j] = L[j];
    done = true;
  }
  ~FirstOrderCapture() { Take(); }
};
}  // namespace

// One path and the branches split from it (the estimator: path_tracer.h). It takes a page because
// the free flight, the three kinds of event (escape, ground, scattering) and the roulette and
// splitting after each all read and write the branch's state (position, direction, shell,
// weights, order), and splitting them into functions would pass that state around per event.
void PathTracer::TracePath(glm::dvec3 start, glm::dvec3 direction, const glm::dvec3& sun, const size_t* idx, int k,
                           Pcg32& rng, double* L, double view_t_end, bool single_scattering, double* L1,
                           double nee_floor_y) const {
  // Segment mode (view_t_end finite): the first flight ends at view_t_end, the path dies there
  // and at the ground (no surface term); later flights are unrestricted.
  const bool segment = std::isfinite(view_t_end);
  double travelled = 0.0;
  for (int j = 0; j < k; ++j) L[j] = 0.0;
  const bool sun_mode = settings_.illumination == Illumination::kSun;
  const bool segment_nee = sun_mode && settings_.segment_nee;
  const int max_order = settings_.max_order > 0 ? settings_.max_order : std::numeric_limits<int>::max();
  FirstOrderCapture first{L1, L, k};
  // Branches split off the path (split_above, in a cloudy atmosphere) wait here; each continues
  // from its vertex with its share of the weight after the branch before it has ended, drawing
  // from the same stream (the same numbers at any thread count).
  struct Branch {
    glm::dvec3 p, d;
    size_t shell;
    int depth;
    double beta[kMaxWavelengths];
  };
  constexpr int kMaxBranches = 64;
  Branch waiting[kMaxBranches];
  int n_waiting = 0;
  Branch first_branch{start, direction, ShellOf(glm::length(start)), 0, {}};
  for (int j = 0; j < k; ++j) first_branch.beta[j] = 1.0;
  // One branch from its vertex until it ends (a `return` ends the branch, not the path).
  auto run_branch = [&](const Branch& from) {
    glm::dvec3 p = from.p, d = from.d;
    size_t s = from.shell;
    double beta[kMaxWavelengths];
    for (int j = 0; j < k; ++j) beta[j] = from.beta[j];
    // `depth` = scattering and reflection events so far; a sun connection made now is of order
    // depth + 1.
    for (int depth = from.depth; depth < 100000; ++depth) {
      if (depth == 1) first.Take();
      double importance = 1.0;  // of the direction the branch leaves the next vertex in
      // Order-1 sun connections are skipped when single scattering is excluded (shadowed fog).
      const bool nee_here = depth + 1 <= max_order && (single_scattering || depth > 0);
      if (segment_nee && nee_here) {
        SegmentSunNee(p, d, beta, idx, k, sun, rng, L,
                      segment && depth == 0 ? view_t_end : std::numeric_limits<double>::infinity(), nee_floor_y);
      }
      // ---- free flight to the next real scattering event, the ground, or space
      enum class Event { kScatter, kGround, kEscape } event = Event::kEscape;
      for (int guard = 0;; ++guard) {
        if (guard > 1000000) throw InternalError("free-flight traversal did not terminate");
        const Shell& sh = shells_[s];
        SphereHit inner = NearSphere(p, d, sh.radius_lo);
        const bool down = inner.hit;
        const double t_exit = down ? inner.t : FarSphere(p, d, sh.radius_hi);
        const double mu_bar = Majorant(s, idx, k);
        // What is left of the view segment from this shell's entry point.
        const double t_limit =
            segment && depth == 0 ? view_t_end - travelled : std::numeric_limits<double>::infinity();
        double t = 0.0;
        bool scattered = false;
        if (mu_bar > 0.0) {
          for (;;) {
            t -= std::log(1.0 - rng.Uniform()) / mu_bar;
            if (t >= t_limit && t_limit <= t_exit) return;  // beyond the view segment
            if (t >= t_exit) break;
            const glm::dvec3 x = p + t * d;
            const AtmosphereModel::Cell cell = model_.Locate(glm::length(x) - model_.bottom_radius_m);
            double ms[kMaxWavelengths], mn[kMaxWavelengths];
            double ps = 0.0, pn = 0.0;
            for (int j = 0; j < k; ++j) {
              ms[j] = model_.Scattering(cell, idx[j]);
              mn[j] = std::max(0.0, mu_bar - model_.Extinction(cell, idx[j]));
              ps += std::abs(beta[j] * ms[j]);
              pn += std::abs(beta[j] * mn[j]);
            }
            if (ps + pn <= 0.0) return;  // every weight is zero
            const double P_s = ps / (ps + pn);
            if (rng.Uniform() < P_s) {
              for (int j = 0; j < k; ++j) beta[j] *= ms[j] / (mu_bar * P_s);
              p = x;
              scattered = true;
              break;
            }
            for (int j = 0; j < k; ++j) beta[j] *= mn[j] / (mu_bar * (1.0 - P_s));
          }
        }
        if (scattered) {
          event = Event::kScatter;
          break;
        }
        p += t_exit * d;
        if (segment && depth == 0) {
          travelled += t_exit;
          if (t_exit >= t_limit) return;  // the segment ends inside this shell
        }
        if (down) {
          if (s == 0) {
            event = Event::kGround;
            // Snap exactly onto the ground sphere.
            p = glm::normalize(p) * model_.bottom_radius_m;
            break;
          }
          --s;
        } else {
          if (s + 1 == shells_.size()) {
            event = Event::kEscape;
            break;
          }
          ++s;
        }
      }

      if (event == Event::kEscape) {
        if (depth == 0) first.Take();  // the unscattered light from space (uniform mode) is order 0
        if (!sun_mode && depth <= max_order) {
          for (int j = 0; j < k; ++j) L[j] += beta[j];  // uniform radiance 1 from space
        }
        return;
      }

      if (event == Event::kGround) {
        if (segment && depth == 0) return;  // fog: the surface is not part of a view segment
        const glm::dvec3 n = glm::normalize(p);
        if (sun_mode && nee_here) SunNee(p, d, true, beta, idx, k, sun, rng, L);
        if (depth + 1 >= max_order && sun_mode) return;
        // Cosine-weighted bounce: f cos / pdf = albedo; where the sun is not hidden (sun_peak_guide)
        // a share of the directions about the sun, f cos / pdf = albedo x (cos / pi) / the mixture.
        double bmax = 0.0;
        for (int j = 0; j < k; ++j) {
          beta[j] *= model_.ground_albedo[idx[j]];
          bmax = std::max(bmax, beta[j]);
        }
        if (bmax <= 0.0) return;
        const double q_sun = sun_mode && segment_nee && !InEarthShadow(p, sun) ? peak_guide_ : 0.0;
        if (q_sun > 0.0) {
          const int nh = settings_.wavelength_mis ? k : 1;
          const int tech = nh > 1 ? std::min(nh - 1, static_cast<int>(rng.Uniform() * nh)) : 0;
          d = rng.Uniform() < q_sun ? SamplePeakAboutSun(idx[tech], sun, rng) : CosineHemisphere(n, rng.Uniform(), rng.Uniform());
          const double cos_n = glm::dot(n, d);
          if (cos_n <= 0.0) return;  // a direction about the sun below the ground's horizon
          const double peak = PeakAboutSunPdf(idx, nh, glm::dot(sun, d));
          const double ratio = cos_n / kPi / ((1.0 - q_sun) * cos_n / kPi + q_sun * peak);
          for (int j = 0; j < k; ++j) beta[j] *= ratio;
          importance = std::max(1.0, q_sun * peak);
        } else {
          d = CosineHemisphere(n, rng.Uniform(), rng.Uniform());
        }
        p += n * 1e-3;  // leave the surface
        s = 0;
      } else {
        // Medium scattering vertex.
        if (sun_mode && !segment_nee && nee_here) SunNee(p, d, false, beta, idx, k, sun, rng, L);
        if (depth + 1 >= max_order && sun_mode) return;
        const AtmosphereModel::Cell cell = model_.Locate(glm::length(p) - model_.bottom_radius_m);
        // Component choice ~ sum_j |b_j| mu_s,c(lambda_j); direction from that component's phase
        // at the hero wavelength; weight by each wavelength's mixture phase / mixture pdf.
        const size_t nc = model_.components.size();
        double sel[32];
        SKYBAKE_CHECK_LE(nc, size_t{32});
        double total = 0.0;
        for (size_t c = 0; c < nc; ++c) {
          sel[c] = 0.0;
          if (!model_.components[c].phase) continue;
          for (int j = 0; j < k; ++j) sel[c] += std::abs(beta[j]) * model_.ComponentScattering(c, cell, idx[j]);
          total += sel[c];
        }
        if (total <= 0.0) return;
        double u = rng.Uniform() * total;
        size_t chosen = 0;
        for (size_t c = 0; c < nc; ++c) {
          if (sel[c] <= 0.0) continue;
          chosen = c;
          if (u < sel[c]) break;
          u -= sel[c];
        }
        // The technique wavelength: the hero, or (wavelength_mis) one of the k drawn uniformly,
        // the pdf then the mixture over the k (one-sample MIS).
        const int nh = settings_.wavelength_mis ? k : 1;
        const int tech = nh > 1 ? std::min(nh - 1, static_cast<int>(rng.Uniform() * nh)) : 0;
        // The vertex's techniques: in the Earth's shadow (twilight_guide) half of the directions
        // from the sunward band; where the sun is not hidden by the planet (sun_peak_guide) a share
        // from the phase function centred on the sun; the rest from the phase function about d.
        glm::dvec3 bn(0.0), bg(0.0), bb(0.0);
        const bool shadowed = sun_mode && segment_nee && InEarthShadow(p, sun);
        const bool guide = settings_.twilight_guide && shadowed && BandFrame(p, sun, &bn, &bg, &bb);
        const double q_band = guide ? 0.5 : 0.0;
        const double q_sun = sun_mode && segment_nee && !shadowed ? peak_guide_ : 0.0;
        glm::dvec3 d_new;
        double mu;
        const double u_tech = q_band + q_sun > 0.0 ? rng.Uniform() : 1.0;
        if (u_tech < q_band + q_sun) {
          d_new = u_tech < q_band ? SampleBand(bn, bg, bb, rng.Uniform(), rng.Uniform())
                                  : SamplePeakAboutSun(idx[tech], sun, rng);
          mu = std::clamp(glm::dot(d, d_new), -1.0, 1.0);
        } else {
          mu = model_.components[chosen].phase->SampleMu(idx[tech], rng.Uniform());
          d_new = RotateAround(d, mu, 2.0 * kPi * rng.Uniform());
        }
        // Mixture pdf (solid angle) of the sampled direction: the component mixture's phase at the
        // technique wavelengths about d, and (q_sun) the peak about the sun.
        auto mixture_pdf = [&](double cos_angle) {
          double pm = 0.0;
          for (int h = 0; h < nh; ++h) {
            for (size_t c = 0; c < nc; ++c) {
              if (sel[c] > 0.0) pm += sel[c] / total * model_.components[c].phase->Eval(idx[h], cos_angle);
            }
          }
          return pm / nh;
        };
        double pdf = (1.0 - q_band - q_sun) * mixture_pdf(mu);
        const double peak = q_sun > 0.0 ? PeakAboutSunPdf(idx, nh, glm::dot(sun, d_new)) : 0.0;
        pdf += q_sun * peak;
        if (q_band > 0.0) pdf += q_band * BandPdf(d_new, bn, bg, bb);
        if (!(pdf > 0.0)) return;
        for (int j = 0; j < k; ++j) beta[j] *= MixturePhase(cell, idx[j], mu) / pdf;
        if (q_sun > 0.0) importance = std::max(1.0, q_sun * peak);
        d = d_new;  // the vertex is inside shell s: the traversal continues from there
      }

      // Russian roulette and splitting on the weight times the direction's importance (1, or
      // q_sun x the phase towards the sun where the vertex guides towards the sun's peak).
      double bmax = 0.0;
      for (int j = 0; j < k; ++j) bmax = std::max(bmax, std::abs(beta[j]));
      const double e = bmax * importance;
      if (depth + 1 >= settings_.russian_roulette_depth) {
        const double q = std::min(1.0, e);
        if (q <= 0.0 || rng.Uniform() >= q) return;
        for (int j = 0; j < k; ++j) beta[j] /= q;
      }
      if (split_above_ > 0.0 && e > split_above_ && n_waiting < kMaxBranches) {
        const int n = std::min(kMaxBranches - n_waiting + 1, static_cast<int>(std::ceil(e)));
        for (int j = 0; j < k; ++j) beta[j] /= n;
        for (int i = 1; i < n; ++i) {
          Branch& w = waiting[n_waiting++];
          w.p = p;
          w.d = d;
          w.shell = s;
          w.depth = depth + 1;
          for (int j = 0; j < k; ++j) w.beta[j] = beta[j];
        }
      }
    }
  };
  run_branch(first_branch);
  while (n_waiting > 0) {
    --n_waiting;
    run_branch(waiting[n_waiting]);
  }
}

glm::dvec3 PathTracer::StartPoint(const glm::dvec3& position) const {
  if (glm::length(position) < model_.bottom_radius_m + 1e-3) return glm::normalize(position) * (model_.bottom_radius_m + 1e-3);
  return position;
}

void PathTracer::SamplePath(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction,
                            uint64_t stream, uint64_t n, bool cosine_hemisphere, double view_t_end,
                            bool single_scattering, double* xyz, double nee_floor_y) const {
  const glm::dvec3 start = StartPoint(position);
  const size_t n_wl = model_.wavelengths();
  const int k = static_cast<int>(std::min<size_t>(static_cast<size_t>(settings_.wavelengths_per_path), n_wl));
  const double scale = static_cast<double>(n_wl) / k;
  Pcg32 rng(settings_.seed, stream, n);
  size_t idx[kMaxWavelengths];
  const size_t hero = std::min(n_wl - 1, static_cast<size_t>(rng.Uniform() * static_cast<double>(n_wl)));
  for (int j = 0; j < k; ++j) idx[j] = (hero + static_cast<size_t>(j) * n_wl / static_cast<size_t>(k)) % n_wl;
  glm::dvec3 d = direction;
  double weight = 1.0;
  if (cosine_hemisphere) {
    d = CosineHemisphere(glm::normalize(position), rng.Uniform(), rng.Uniform());
    weight = kPi;  // E = pi E_cos[L]
  }
  double L[kMaxWavelengths];
  TracePath(start, d, sun_direction, idx, k, rng, L, view_t_end, single_scattering, nullptr, nee_floor_y / weight);
  for (int c = 0; c < 3; ++c) xyz[c] = 0.0;
  for (int j = 0; j < k; ++j) {
    for (int c = 0; c < 3; ++c) xyz[c] += scale * weight * xyz_weights_[idx[j]][static_cast<size_t>(c)] * L[j];
  }
}

void PathTracer::ColorPath(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction,
                           uint64_t stream, uint64_t n, double* xyz, double nee_floor_y) const {
  SamplePath(position, direction, sun_direction, stream, n, false, std::numeric_limits<double>::infinity(), true, xyz,
             nee_floor_y);
}

ColorEstimate PathTracer::Estimate(const glm::dvec3& position, const glm::dvec3& direction,
                                   const glm::dvec3& sun_direction, uint64_t stream, bool cosine_hemisphere,
                                   double view_t_end, bool single_scattering) const {
  RunningMoments acc[3];  // X, Y, Z
  uint64_t n = 0;
  double floor_y = 0.0;  // nee_roulette x the estimate of the batches so far
  for (;;) {
    for (uint64_t b = 0; b < settings_.batch_paths; ++b, ++n) {
      double xyz[3];
      SamplePath(position, direction, sun_direction, stream, n, cosine_hemisphere, view_t_end, single_scattering, xyz,
                 floor_y);
      for (int c = 0; c < 3; ++c) acc[c].Add(xyz[c]);
    }
    if (cloud_estimators_) floor_y = settings_.nee_roulette * std::abs(acc[1].mean);
    if (n >= MinPaths()) {
      const RunningMoments& y = acc[1];
      // An all-zero start (e.g. a view into the Earth's shadow) is not a converged estimate:
      // keep sampling until the floor or max_paths decides.
      const bool zero_so_far = y.mean == 0.0 && y.m2 == 0.0;
      const double tolerance = std::max(settings_.target_relative_error * std::abs(y.mean), settings_.absolute_error_floor);
      const bool reliable = settings_.stderr_reliability <= 0.0 || y.StdErrRelativeUncertainty() <= settings_.stderr_reliability;
      if ((!zero_so_far && y.StdErr() <= tolerance && reliable) || n >= settings_.max_paths) break;
    }
  }
  ColorEstimate e;
  e.paths = n;
  for (int c = 0; c < 3; ++c) {
    e.xyz[static_cast<size_t>(c)] = acc[c].mean;
    e.xyz_stderr[static_cast<size_t>(c)] = acc[c].StdErr();
  }
  return e;
}

ColorEstimate PathTracer::Radiance(const glm::dvec3& position, const glm::dvec3& direction,
                                   const glm::dvec3& sun_direction, uint64_t stream) const {
  return Estimate(position, direction, sun_direction, stream, false, std::numeric_limits<double>::infinity(), true);
}

ColorEstimate PathTracer::SegmentRadiance(const glm::dvec3& position, const glm::dvec3& direction,
                                          const glm::dvec3& sun_direction, double t_end, uint64_t stream,
                                          bool single_scattering) const {
  SKYBAKE_CHECK(t_end >= 0.0 && std::isfinite(t_end));
  return Estimate(position, direction, sun_direction, stream, false, t_end, single_scattering);
}

ColorEstimate PathTracer::Irradiance(const glm::dvec3& position, const glm::dvec3& sun_direction, uint64_t stream) const {
  return Estimate(position, glm::normalize(position), sun_direction, stream, true,
                  std::numeric_limits<double>::infinity(), true);
}

void PathTracer::SpectralRadiance(const glm::dvec3& position, const glm::dvec3& direction,
                                  const glm::dvec3& sun_direction, const std::vector<size_t>& wavelengths,
                                  uint64_t paths, uint64_t stream, std::vector<double>* mean,
                                  std::vector<double>* stderr_out) const {
  const int k = static_cast<int>(wavelengths.size());
  SKYBAKE_CHECK(k >= 1 && k <= kMaxWavelengths);
  std::vector<double> m(static_cast<size_t>(k), 0.0), m2(static_cast<size_t>(k), 0.0);
  glm::dvec3 start = position;
  if (glm::length(start) < model_.bottom_radius_m + 1e-3) start = glm::normalize(position) * (model_.bottom_radius_m + 1e-3);
  for (uint64_t n = 0; n < paths; ++n) {
    Pcg32 rng(settings_.seed, stream, n);
    double L[kMaxWavelengths];
    TracePath(start, direction, sun_direction, wavelengths.data(), k, rng, L);
    for (int j = 0; j < k; ++j) {
      const double delta = L[j] - m[static_cast<size_t>(j)];
      m[static_cast<size_t>(j)] += delta / static_cast<double>(n + 1);
      m2[static_cast<size_t>(j)] += delta * (L[j] - m[static_cast<size_t>(j)]);
    }
  }
  mean->assign(m.begin(), m.end());
  stderr_out->resize(static_cast<size_t>(k));
  for (int j = 0; j < k; ++j) {
    const double var = paths > 1 ? m2[static_cast<size_t>(j)] / static_cast<double>(paths - 1) : 0.0;
    (*stderr_out)[static_cast<size_t>(j)] = std::sqrt(var / static_cast<double>(paths));
  }
}

}  // namespace skybake
