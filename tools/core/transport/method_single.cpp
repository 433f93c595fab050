#include "transport/method_single.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "atmosphere/ray_sphere.h"
#include "io/error.h"
#include "transport/path_tracer.h"

namespace skybake {

namespace {
constexpr double kPi = std::numbers::pi;

// 3-point Gauss-Legendre on [-1, 1] (Abramowitz & Stegun 25.4.29): nodes 0, +-sqrt(3/5),
// weights 8/9, 5/9.
constexpr double kGl3X = 0.7745966692414834;
constexpr double kGl3W0 = 8.0 / 9.0, kGl3W1 = 5.0 / 9.0;
// 2-point: +-1/sqrt(3), weights 1.
constexpr double kGl2X = 0.5773502691896257;

// (1 - e^-x)/x and (1 - (1 + x) e^-x)/x^2, with their Taylor series near 0 (error < 1e-10).
inline void LinExpWeights(double x, double e, double* f0, double* f1) {
  if (x < 1e-2) {
    *f0 = 1.0 - x * (0.5 - x * (1.0 / 6.0 - x / 24.0));
    *f1 = 0.5 - x * (1.0 / 3.0 - x * (0.125 - x / 30.0));
  } else {
    *f0 = (1.0 - e) / x;
    *f1 = (1.0 - (1.0 + x) * e) / (x * x);
  }
}
}  // namespace

// ---------------------------------------------------------------------------- level tables

LevelTables::LevelTables(const AtmosphereModel& m) : model(m), nl(m.levels()), nw(m.wavelengths()) {
  extinction.resize(nl * nw);
  total_scattering.assign(nl * nw, 0.0);
  for (size_t l = 0; l < nl; ++l) {
    const AtmosphereModel::Cell c = l + 1 < nl ? AtmosphereModel::Cell{l, 0.0} : AtmosphereModel::Cell{nl - 2, 1.0};
    for (size_t w = 0; w < nw; ++w) extinction[l * nw + w] = m.Extinction(c, w);
  }
  for (size_t k = 0; k < m.components.size(); ++k) {
    if (!m.components[k].phase) continue;
    scattering.push_back(m.components[k].scattering);
    phase.push_back(m.components[k].phase.get());
    for (size_t i = 0; i < nl * nw; ++i) total_scattering[i] += m.components[k].scattering[i];
  }
}

void LevelTables::ExtinctionAt(double z, double* out) const {
  const AtmosphereModel::Cell c = model.Locate(z);
  const double* a = &extinction[c.i * nw];
  const double* b = a + nw;
  for (size_t w = 0; w < nw; ++w) out[w] = a[w] + (b[w] - a[w]) * c.t;
}

// ---------------------------------------------------------------------------- exact optical depth

void ExactOpticalDepth(const LevelTables& t, double r0, double mu, double length, double* tau) {
  if (!(length > 0.0)) return;
  const AtmosphereModel& m = t.model;
  const double R = m.bottom_radius_m, R_top = m.top_radius_m;
  const size_t nw = t.nw;
  const double p2 = ImpactParameterSquared(r0, mu);
  const double s0 = r0 * mu, s1 = s0 + length;
  // One monotone part: s in [a, b], 0 <= a < b, r(s) = sqrt(p2 + s^2) increasing.
  auto part = [&](double a, double b) {
    double ra = std::sqrt(p2 + a * a);
    if (ra >= R_top) return;
    size_t i = m.Locate(ra - R).i;
    double s_lo = a;
    const double rb = std::sqrt(p2 + b * b);
    while (s_lo < b) {
      const double rho_lo = R + m.altitude_m[i], rho_hi = R + m.altitude_m[i + 1];
      double s_hi = b;
      const bool last = rho_hi >= rb || i + 2 >= t.nl;
      if (!last) s_hi = std::min(b, std::sqrt(std::max(0.0, rho_hi * rho_hi - p2)));
      const double ds = s_hi - s_lo;
      if (ds > 0.0) {
        // u = int (r(s) - rho_lo)/(rho_hi - rho_lo) ds by 3-point Gauss-Legendre, with
        // r - rho_lo = (p2 + s^2 - rho_lo^2)/(r + rho_lo) (no cancellation).
        const double c = 0.5 * (s_lo + s_hi), h = 0.5 * ds;
        const double q = p2 - rho_lo * rho_lo;
        auto f = [&](double s) {
          const double r = std::sqrt(p2 + s * s);
          return (q + s * s) / (r + rho_lo);
        };
        const double u = h * (kGl3W0 * f(c) + kGl3W1 * (f(c - kGl3X * h) + f(c + kGl3X * h))) / (rho_hi - rho_lo);
        const double w_lo = ds - u, w_hi = u;
        const double* e0 = &t.extinction[i * nw];
        const double* e1 = e0 + nw;
        for (size_t w = 0; w < nw; ++w) tau[w] += w_lo * e0[w] + w_hi * e1[w];
      }
      if (last) break;
      s_lo = s_hi;
      ++i;
    }
  };
  if (s1 <= 0.0) {
    part(-s1, -s0);
  } else if (s0 >= 0.0) {
    part(s0, s1);
  } else {
    part(0.0, -s0);
    part(0.0, s1);
  }
}

// ---------------------------------------------------------------------------- transmittance table

TransmittanceTable::TransmittanceTable(const LevelTables& t, int n_mu, int n_r)
    : t_(t), n_mu_(n_mu), n_r_(n_r), R_(t.model.bottom_radius_m), R_top_(t.model.top_radius_m) {
  SKYBAKE_CHECK_GE(n_mu, 2);
  SKYBAKE_CHECK_GE(n_r, 2);
  H_ = DistanceToHorizon(R_top_, R_);
  const size_t nw = t.nw;
  tau_.assign(static_cast<size_t>(n_mu) * n_r * nw, 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, n_r), [&](const tbb::blocked_range<int>& rows) {
    for (int ir = rows.begin(); ir != rows.end(); ++ir) {
      const double rho = H_ * ir / (n_r - 1);
      const double r = std::sqrt(rho * rho + R_ * R_);
      const double d_min = R_top_ - r, d_max = rho + H_;
      for (int im = 0; im < n_mu; ++im) {
        const double d = d_min + (d_max - d_min) * im / (n_mu - 1);
        const double mu = d <= 0.0 ? 1.0 : std::clamp((H_ * H_ - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
        ExactOpticalDepth(t_, r, mu, d, &tau_[(static_cast<size_t>(ir) * n_mu + im) * nw]);
      }
    }
  });
}

double TransmittanceTable::HorizonMu(double r) const {
  return HorizonMuOfSquares(r, R_);
}

void TransmittanceTable::OpticalDepth(double r, double mu, double* tau) const {
  r = std::clamp(r, R_, R_top_);
  const double rho = DistanceToHorizon(r, R_);
  const double d = DistanceToTopAtmosphereBoundary(r, mu, R_top_);
  const double d_min = R_top_ - r, d_max = rho + H_;
  const double x_mu = std::clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
  const double x_r = std::clamp(rho / H_, 0.0, 1.0);
  const double fm = x_mu * (n_mu_ - 1), fr = x_r * (n_r_ - 1);
  const int im = std::min(static_cast<int>(fm), n_mu_ - 2), ir = std::min(static_cast<int>(fr), n_r_ - 2);
  const double tm = fm - im, tr = fr - ir;
  const size_t nw = t_.nw;
  const double* a = &tau_[(static_cast<size_t>(ir) * n_mu_ + im) * nw];
  const double* b = a + nw;
  const double* c = a + static_cast<size_t>(n_mu_) * nw;
  const double* e = c + nw;
  const double w00 = (1 - tm) * (1 - tr), w01 = tm * (1 - tr), w10 = (1 - tm) * tr, w11 = tm * tr;
  for (size_t w = 0; w < nw; ++w) tau[w] = w00 * a[w] + w01 * b[w] + w10 * c[w] + w11 * e[w];
}

// ---------------------------------------------------------------------------- sun disk

SunDiskQuadrature::SunDiskQuadrature(const SunModel& sun, size_t nw, int rings, int sectors) {
  if (rings <= 0) {
    points.push_back({1.0, 0.0, 0.0, sun.irradiance});
    return;
  }
  SKYBAKE_CHECK_GE(sectors, 1);
  const double cos_max = std::cos(sun.angular_radius_rad);
  std::vector<double> total(nw, 0.0);
  std::vector<std::vector<double>> ring_e(static_cast<size_t>(rings), std::vector<double>(nw, 0.0));
  for (int k = 0; k < rings; ++k) {
    const double c_hi = 1.0 - (1.0 - cos_max) * k / rings, c_lo = 1.0 - (1.0 - cos_max) * (k + 1) / rings;
    // int_ring L dOmega = 2 pi int_{c_lo}^{c_hi} L(acos c) dc, midpoint rule on 64 sub-rings.
    constexpr int kSub = 64;
    for (int j = 0; j < kSub; ++j) {
      const double c = c_hi - (c_hi - c_lo) * (j + 0.5) / kSub;
      const double alpha = std::acos(std::min(1.0, c));
      for (size_t w = 0; w < nw; ++w) ring_e[k][w] += 2.0 * kPi * (c_hi - c_lo) / kSub * sun.Radiance(w, alpha);
    }
    for (size_t w = 0; w < nw; ++w) total[w] += ring_e[k][w];
  }
  for (int k = 0; k < rings; ++k) {
    const double c_mid = 1.0 - (1.0 - cos_max) * (k + 0.5) / rings;
    std::vector<double> wt(nw);
    // Scale so that the points carry E_0 exactly (SunModel::Radiance is normalised to E_0 up to
    // its small-angle approximation, ~2e-5).
    for (size_t w = 0; w < nw; ++w) wt[w] = total[w] > 0.0 ? ring_e[k][w] / total[w] * sun.irradiance[w] / sectors : 0.0;
    for (int q = 0; q < sectors; ++q) {
      points.push_back({c_mid, std::acos(c_mid), 2.0 * kPi * (q + 0.5) / sectors, wt});
    }
  }
}

std::vector<glm::dvec3> SunDiskQuadrature::Directions(const glm::dvec3& sun) const {
  std::vector<glm::dvec3> d;
  for (const Point& p : points) d.push_back(p.alpha == 0.0 ? sun : RotateAround(sun, p.cos_alpha, p.phi));
  return d;
}

// ---------------------------------------------------------------------------- geometry

RayExtent ExtentOf(const AtmosphereModel& m, const glm::dvec3& x, const glm::dvec3& v) {
  RayExtent e;
  const double b = glm::dot(x, v), r2 = glm::dot(x, x);
  const double R = m.bottom_radius_m;
  if (b < 0.0 && SphereDiscriminantDot(b, r2, R) >= 0.0) {
    const double t0 = DistanceToSphereInDot(b, r2, R);
    if (t0 >= -1e-9 * R) {
      e.hits_ground = true;
      e.ground = std::max(0.0, t0);
    }
  }
  // A ray from outside the atmosphere that misses it has no length (the far root alone would be -b).
  e.top = SphereDiscriminantDot(b, r2, m.top_radius_m) >= 0.0 ? ClampDistance(DistanceToSphereOutDot(b, r2, m.top_radius_m)) : 0.0;
  return e;
}

// ---------------------------------------------------------------------------- the march

namespace {
std::vector<double> Ladder(double top, double dz_min, double dz_rel) {
  std::vector<double> z;
  for (double a = 0.0; a < top; a += std::max(dz_min, dz_rel * a)) z.push_back(a);
  return z;
}
}  // namespace

SingleScatteringModel::SingleScatteringModel(const AtmosphereModel& model, const MarchSettings& s)
    : model_(model),
      settings_(s),
      tables_(model),
      transmittance_(tables_, s.table_mu, s.table_r),
      disk_(model.sun, model.wavelengths(), s.disk_rings, s.disk_sectors) {
  SKYBAKE_CHECK_GT(s.dz_min_m, 0.0);
  SKYBAKE_CHECK_GE(s.dz_rel, 0.0);
  SKYBAKE_CHECK_GT(s.max_piece_m, 0.0);
  ladder_ = Ladder(model.altitude_m.back(), s.dz_min_m, s.dz_rel);
}

std::vector<double> SingleScatteringModel::Nodes(const glm::dvec3& x, const glm::dvec3& v,
                                                 const std::vector<glm::dvec3>& sun_dirs, double length,
                                                 const RayOptions& o) const {
  const double R = model_.bottom_radius_m;
  const double dz_min = o.dz_min_m > 0 ? o.dz_min_m : settings_.dz_min_m;
  const double dz_rel = o.dz_rel > 0 ? o.dz_rel : settings_.dz_rel;
  const double max_piece = o.max_piece_m > 0 ? o.max_piece_m : settings_.max_piece_m;
  std::vector<double> t = {0.0, length};
  const double r0 = glm::length(x);
  const double mu = glm::dot(x, v) / r0;
  const double p2 = ImpactParameterSquared(r0, mu);
  const double s0 = r0 * mu;
  auto add = [&](double tt) {
    if (tt > 0.0 && tt < length) t.push_back(tt);
  };
  // Altitude ladder crossings (both sides of the closest approach).
  const bool own = o.dz_min_m > 0 || o.dz_rel > 0;
  const std::vector<double> custom = own ? Ladder(model_.altitude_m.back(), dz_min, dz_rel) : std::vector<double>{};
  for (double z : own ? custom : ladder_) {
    const double rho = R + z;
    const double q = rho * rho - p2;
    if (q < 0.0) continue;
    const double sk = std::sqrt(q);
    add(sk - s0);
    add(-sk - s0);
  }
  add(-s0);  // the closest approach (lowest altitude of the ray)
  // Shadow boundaries: |y_perp| = R behind the planet, y = x + t v, perp to each sun direction.
  for (const glm::dvec3& w : sun_dirs) {
    const glm::dvec3 xp = x - glm::dot(x, w) * w, vp = v - glm::dot(v, w) * w;
    const double a = glm::dot(vp, vp), b = 2.0 * glm::dot(xp, vp), c = glm::dot(xp, xp) - R * R;
    if (a < 1e-300) continue;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) continue;
    const double sq = std::sqrt(disc);
    for (double tt : {(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)}) {
      if (glm::dot(x + tt * v, w) < 0.0) add(tt);
    }
  }
  std::sort(t.begin(), t.end());
  std::vector<double> out;
  const double eps = 1e-9 * std::max(1.0, length);
  for (double tt : t) {
    if (!out.empty() && tt - out.back() <= eps) continue;
    if (!out.empty()) {
      const double d = tt - out.back();
      const int n = static_cast<int>(std::ceil(d / max_piece));
      const double t0 = out.back();
      for (int k = 1; k < n; ++k) out.push_back(t0 + d * k / n);
    }
    out.push_back(tt);
  }
  if (out.back() < length) out.back() = length;
  return out;
}

void SingleScatteringModel::MarchRay(const glm::dvec3& x, const glm::dvec3& v, const glm::dvec3& sun,
                                     const RayOptions& o, double* L, double* f_ms) const {
  const size_t nw = tables_.nw, nc = tables_.phase.size();
  std::fill(L, L + nw, 0.0);
  if (f_ms) std::fill(f_ms, f_ms + nw, 0.0);
  const RayExtent ext = ExtentOf(model_, x, v);
  const double length = ext.length();
  const double R = model_.bottom_radius_m;

  // Sun points, their directions and phase x weight per component (constant along the ray).
  static const SunDiskQuadrature::Point kCentre{1.0, 0.0, 0.0, {}};
  std::vector<const SunDiskQuadrature::Point*> pts;
  std::vector<glm::dvec3> dirs;
  if (o.point_sun) {
    pts.push_back(&kCentre);
    dirs.push_back(sun);
  } else {
    for (const SunDiskQuadrature::Point& p : disk_.points) pts.push_back(&p);
    dirs = disk_.Directions(sun);
  }
  const size_t nd = pts.size();
  std::vector<double> a(nd * nc * nw);  // [d][c][wl]: P_c(v.w_d) x weight_d
  for (size_t d = 0; d < nd; ++d) {
    const double nu = glm::dot(v, dirs[d]);
    for (size_t c = 0; c < nc; ++c) {
      for (size_t w = 0; w < nw; ++w) {
        const double p = o.sun_phase ? tables_.phase[c]->Eval(w, nu) : 1.0 / (4.0 * kPi);
        double wt;
        if (o.point_sun) {
          wt = o.unit_sun ? 1.0 : model_.sun.irradiance[w];
        } else {
          wt = pts[d]->weight[w];
          if (o.unit_sun) wt = model_.sun.irradiance[w] > 0.0 ? wt / model_.sun.irradiance[w] : 0.0;
        }
        a[(d * nc + c) * nw + w] = p * wt;
      }
    }
  }

  std::vector<double> T(nw, 1.0), S0(nw), S1(nw), F0(nw), F1(nw), tau(nw), e0(nw), e1(nw), sig(nw);
  auto source = [&](double t, double* S, double* F) {
    const glm::dvec3 y = x + t * v;
    const double r = glm::length(y);
    const glm::dvec3 up = y / r;
    const AtmosphereModel::Cell cell = model_.Locate(r - R);
    std::fill(S, S + nw, 0.0);
    for (size_t w = 0; w < nw; ++w) {
      const double* ts = &tables_.total_scattering[cell.i * nw + w];
      sig[w] = ts[0] + (ts[nw] - ts[0]) * cell.t;
    }
    if (F) std::copy(sig.begin(), sig.end(), F);
    const double horizon = transmittance_.HorizonMu(std::max(r, R));
    for (size_t d = 0; d < nd; ++d) {
      const double mu_d = glm::dot(up, dirs[d]);
      if (mu_d < horizon) continue;  // the planet hides this part of the sun
      transmittance_.OpticalDepth(r, mu_d, tau.data());
      for (size_t w = 0; w < nw; ++w) {
        double ps = 0.0;
        for (size_t c = 0; c < nc; ++c) {
          const double* sc = &tables_.scattering[c][cell.i * nw + w];
          ps += (sc[0] + (sc[nw] - sc[0]) * cell.t) * a[(d * nc + c) * nw + w];
        }
        S[w] += ps * std::exp(-tau[w]);
      }
    }
    if (o.extra) o.extra->Add(r - R, glm::dot(up, sun), sig.data(), S);
  };

  if (length > 0.0) {
    const std::vector<double> t = Nodes(x, v, dirs, length, o);
    source(t[0], S0.data(), f_ms ? F0.data() : nullptr);
    for (size_t k = 0; k + 1 < t.size(); ++k) {
      source(t[k + 1], S1.data(), f_ms ? F1.data() : nullptr);
      const double D = t[k + 1] - t[k];
      // The piece's optical depth by 2-point Gauss-Legendre in t.
      const double c = t[k] + 0.5 * D;
      tables_.ExtinctionAt(glm::length(x + (c - kGl2X * 0.5 * D) * v) - R, e0.data());
      tables_.ExtinctionAt(glm::length(x + (c + kGl2X * 0.5 * D) * v) - R, e1.data());
      for (size_t w = 0; w < nw; ++w) {
        const double xx = 0.5 * D * (e0[w] + e1[w]);
        const double e = std::exp(-xx);
        double f0, f1;
        LinExpWeights(xx, e, &f0, &f1);
        L[w] += T[w] * D * (S0[w] * f0 + (S1[w] - S0[w]) * f1);
        if (f_ms) f_ms[w] += T[w] * D * (F0[w] * f0 + (F1[w] - F0[w]) * f1);
        T[w] *= e;
      }
      std::swap(S0, S1);
      std::swap(F0, F1);
    }
  }

  // The ground's reflection of the direct sun (Lambertian, first order).
  if (ext.hits_ground && o.ground) {
    const glm::dvec3 g = x + length * v;
    const glm::dvec3 up = glm::normalize(g);
    std::vector<double> eg(nw, 0.0);
    for (size_t d = 0; d < nd; ++d) {
      const double mu_d = glm::dot(up, dirs[d]);
      if (mu_d <= 0.0) continue;
      transmittance_.OpticalDepth(R, mu_d, tau.data());
      for (size_t w = 0; w < nw; ++w) {
        double wt = o.point_sun ? model_.sun.irradiance[w] : pts[d]->weight[w];
        if (o.unit_sun) wt = o.point_sun ? 1.0 : (model_.sun.irradiance[w] > 0.0 ? wt / model_.sun.irradiance[w] : 0.0);
        eg[w] += wt * mu_d * std::exp(-tau[w]);
      }
    }
    for (size_t w = 0; w < nw; ++w) L[w] += T[w] * model_.ground_albedo[w] / kPi * eg[w];
  }
}

// ---------------------------------------------------------------------------- the method

const QualityTable<MarchSettings>& SingleMarchPresets() {
  static const QualityTable<MarchSettings> presets = {{
      // low: a point sun
      MarchSettings{.dz_min_m = 500.0, .dz_rel = 0.3, .max_piece_m = 100e3, .disk_rings = 0, .disk_sectors = 4,
                    .table_mu = 64, .table_r = 16},
      // medium
      MarchSettings{.dz_min_m = 150.0, .dz_rel = 0.12, .max_piece_m = 30e3, .disk_rings = 1, .disk_sectors = 4,
                    .table_mu = 128, .table_r = 32},
      // high
      MarchSettings{.dz_min_m = 50.0, .dz_rel = 0.05, .max_piece_m = 10e3, .disk_rings = 3, .disk_sectors = 6,
                    .table_mu = 256, .table_r = 64},
  }};
  return presets;
}

MarchSettings SingleMarchSettings(Quality quality) { return SingleMarchPresets()[quality]; }

namespace {

std::string DescribeMarch(const MarchSettings& s) {
  return fmt::format(
      "altitude_ladder: {{dz_min_m: {}, dz_rel: {}}}\nmax_piece_m: {}\nsun_disk_points: {}\n"
      "transmittance_table: {{mu: {}, r: {}}}\n",
      s.dz_min_m, s.dz_rel, s.max_piece_m, s.disk_rings <= 0 ? 1 : s.disk_rings * s.disk_sectors, s.table_mu, s.table_r);
}

class SingleMethod : public SkyMethod {
 public:
  SingleMethod(const AtmosphereModel& model, const SkyMethodOptions& o)
      : quality_(o.quality), ss_(model, SingleMarchSettings(o.quality)) {}
  std::string Name() const override { return "single"; }
  std::string Describe() const override {
    return "method: single\nquality: " + QualityName(quality_) + "\n" + DescribeMarch(ss_.settings());
  }
  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    const AtmosphereModel& m = ss_.model();
    const size_t nw = m.wavelengths();
    const glm::dvec3 x(0, 0, m.bottom_radius_m + observer_altitude_m);
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
    out->assign(dirs.size() * nw, 0.0);
    SingleScatteringModel::RayOptions o;
    for (size_t d = 0; d < dirs.size(); ++d) {
      const glm::dvec3 v = glm::normalize(glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]));
      ss_.MarchRay(x, v, sun, o, out->data() + d * nw);
    }
  }
  // Radiance is single scattering (and the ground's first reflection) only.
  bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad,
                                const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const override {
    Radiance(observer_altitude_m, sun_zenith_rad, dirs, out);
    return true;
  }

 private:
  Quality quality_;
  SingleScatteringModel ss_;
};

}  // namespace

std::string DescribeMarchSettings(const MarchSettings& s) { return DescribeMarch(s); }

std::unique_ptr<SkyMethod> MakeSingleMethod(const AtmosphereModel& model, const SkyMethodOptions& options) {
  return std::make_unique<SingleMethod>(model, options);
}

}  // namespace skybake
