#include "transport/orders/sun_tables.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>

#include "atmosphere/ray_sphere.h"
#include "io/fast_exp.h"

namespace skybake::orders {

namespace {

constexpr int kDisk = 16;

// Optical depths (unscaled, truncated part) along a ray from r with cosine mu to the top, by
// 2-point Gauss-Legendre on `pieces` pieces; false if it hits the ground.
bool RayDepth(const AtmosphereModel& m, const Medium& md, int pieces, double r, double mu, std::vector<double>* tau,
              std::vector<double>* tau_f) {
  const size_t nw = md.nw;
  const double R = m.bottom_radius_m, top = m.top_radius_m;
  tau->assign(nw, 0.0);
  tau_f->assign(nw, 0.0);
  if (RayIntersectsGround(r, mu, R)) return false;
  const double length = DistanceToSphereOut(r, mu, top);
  const double h = length / pieces;
  static const double kG = 0.5773502691896257;
  std::vector<float> st(nw), sts(nw);
  for (int p = 0; p < pieces; ++p) {
    for (double g : {-kG, kG}) {
      const double t = (p + 0.5 + 0.5 * g) * h;
      const double rr = RadiusAt(r, mu, t);
      const AtmosphereModel::Cell cell = m.Locate(rr - R);  // one lookup for both media
      md.SigmaT(cell, false, st.data());
      md.SigmaT(cell, true, sts.data());
      for (size_t w = 0; w < nw; ++w) {
        (*tau)[w] += 0.5 * h * st[w];
        (*tau_f)[w] += 0.5 * h * (st[w] - sts[w]);
      }
    }
  }
  return true;
}

// The solar disk's weights in elevation: offsets delta_i = y_i alpha across the disk, weights =
// chord length x limb darkening (mean over the wavelengths' coefficients, a stated
// simplification: the limb darkening shapes the penumbra only), 16-point midpoint rule.
void DiskWeights(const AtmosphereModel& m, std::vector<double>* delta, std::vector<double>* weight) {
  const double alpha = m.sun.angular_radius_rad;
  delta->assign(kDisk, 0.0);
  weight->assign(kDisk, 0.0);
  double wsum = 0.0;
  for (int i = 0; i < kDisk; ++i) {
    const double y = -1.0 + (i + 0.5) * 2.0 / kDisk;  // vertical position on the disk / radius
    (*delta)[i] = y * alpha;
    // Integrate the limb-darkened radiance along the chord at height y (32 points).
    double chord = 0.0;
    const double half = std::sqrt(1.0 - y * y);
    for (int q = 0; q < 32; ++q) {
      const double x = -half + (q + 0.5) * 2.0 * half / 32;
      const double rr = std::min(1.0, std::sqrt(x * x + y * y));
      const double mu = std::sqrt(1.0 - rr * rr);
      double ld = 1.0;
      if (!m.sun.limb_coefficients.empty()) {
        ld = 0.0;
        double p = 1.0;
        const std::array<double, 6>& a = m.sun.limb_coefficients[m.sun.limb_coefficients.size() / 2];
        for (int c = 0; c < 6; ++c) {
          ld += a[static_cast<size_t>(c)] * p;
          p *= mu;
        }
      }
      chord += ld * 2.0 * half / 32;
    }
    (*weight)[i] = chord;
    wsum += chord;
  }
  for (double& v : *weight) v /= wsum;
}

// tb->t: each node's transmittance averaged over the disk points (base at the nodes, blended to
// each point's elevation), then the logarithms for the blend of TransmittanceAt.
void AverageOverDisk(const std::vector<float>& base, const std::vector<Lerp>& disk_at, const std::vector<double>& weight,
                     size_t nr, size_t nt, size_t nw, SunTable* tb) {
  tb->loc = IntervalLocator(tb->r);
  tb->t.assign(nr * nt * nw, 0.0f);
  // Each node sums its disk points in the same order whichever thread takes its radius.
  tbb::parallel_for(size_t{0}, nr, [&](size_t i) {
    for (size_t j = 0; j < nt; ++j) {
      for (int d = 0; d < kDisk; ++d) {
        const Lerp& l = disk_at[j * kDisk + static_cast<size_t>(d)];
        const float* a = &base[(i * nt + l.i) * nw];
        const float* b = &base[(i * nt + l.i + 1) * nw];
        const float t = static_cast<float>(l.t), wt = static_cast<float>(weight[d]);
        float* o = &tb->t[(i * nt + j) * nw];
        for (size_t w = 0; w < nw; ++w) o[w] += wt * (a[w] + (b[w] - a[w]) * t);
      }
    }
  });
  tb->lt.assign(tb->t.size(), 0.0f);
  tb->pos.assign(tb->t.size() / nw, 1);
  tbb::parallel_for(size_t{0}, tb->pos.size(), [&](size_t n) {
    for (size_t w = 0; w < nw; ++w) {
      const float v = tb->t[n * nw + w];
      if (v > 0.0f) tb->lt[n * nw + w] = std::log(v);
      else tb->pos[n] = 0;
    }
  });
  tb->first.resize(tb->pos.size());
  for (size_t n = 0; n < tb->first.size(); ++n) tb->first[n] = tb->t[n * nw];
}

}  // namespace

SunTables BuildSunTables(const AtmosphereModel& m, const Medium& md, const OrdersSettings& s) {
  SunTables st;
  const size_t nw = md.nw;
  st.nw = nw;
  const double R = m.bottom_radius_m, H = m.top_radius_m - R;
  const int nr = s.sun_nr;
  // Radius nodes of both tables: uniform in s(h) = (tau(0,h)/tau(0,H) + (h/H)^0.5) / 2, tau the
  // vertical optical depth at the grid's shortest wavelength - half the nodes quadratic in altitude
  // (dense near the ground), half where the extinction is ("Sun transmittance" in
  // docs/sky-methods.md).
  const double tau_top = std::max(m.VerticalOpticalDepth(0.0, H, 0), 1e-12);
  auto s_of = [&](double h) { return 0.5 * (m.VerticalOpticalDepth(0.0, h, 0) / tau_top + std::sqrt(h / H)); };
  for (double h : AltitudesUniformIn(s_of, nr, H)) st.plain.r.push_back(R + h);
  st.star.r = st.plain.r;
  // Sun zenith nodes (deg): 1 deg to 80, sun_low_step_deg (0.1) to 110 (the horizon and the Earth's
  // shadow), 1 deg to 125.
  for (double a = 0; a < 80; a += 1.0) st.theta_deg.push_back(a);
  const int n_low = static_cast<int>(std::lround(30.0 / s.sun_low_step_deg));
  for (int k = 0; k < n_low; ++k) st.theta_deg.push_back(80.0 + k * s.sun_low_step_deg);
  for (double a = 110; a <= 125 + 1e-9; a += 1.0) st.theta_deg.push_back(a);
  const size_t nt = st.theta_deg.size();
  st.theta_loc = IntervalLocator(st.theta_deg);
  std::vector<double> delta, weight;
  DiskWeights(m, &delta, &weight);
  // The optical depths: one ray per (radius, sun node) gives both tables' (they share their radii).
  const size_t nrt = static_cast<size_t>(nr) * nt;
  std::vector<float> base_plain(nrt * nw), base_star(nrt * nw);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nrt, 8), [&](const tbb::blocked_range<size_t>& rg) {
    std::vector<double> tau, tau_f;
    for (size_t k = rg.begin(); k != rg.end(); ++k) {
      const size_t i = k / nt, j = k % nt;
      const bool clear = RayDepth(m, md, s.fine, st.plain.r[i], std::cos(st.theta_deg[j] * kDeg), &tau, &tau_f);
      for (size_t w = 0; w < nw; ++w) {
        base_plain[k * nw + w] = clear ? static_cast<float>(std::exp(-tau[w])) : 0.0f;
        base_star[k * nw + w] = clear ? static_cast<float>(std::exp(-(tau[w] - tau_f[w]))) : 0.0f;
      }
    }
  });
  // The disk's elevation offsets located once per (sun node, disk point), for every radius.
  std::vector<Lerp> disk_at(nt * kDisk);
  for (size_t j = 0; j < nt; ++j) {
    for (int d = 0; d < kDisk; ++d) disk_at[j * kDisk + static_cast<size_t>(d)] = Locate(st.theta_deg, st.theta_deg[j] - delta[d] / kDeg);
  }
  AverageOverDisk(base_plain, disk_at, weight, static_cast<size_t>(nr), nt, nw, &st.plain);
  AverageOverDisk(base_star, disk_at, weight, static_cast<size_t>(nr), nt, nw, &st.star);
  return st;
}

SunTables SliceSunTables(const SunTables& sun, const std::vector<size_t>& ws) {
  SunTables b = sun;
  b.nw = ws.size();
  for (SunTable* tb : {&b.plain, &b.star}) {
    tb->t = SliceColumns(tb->t, sun.nw, ws);
    tb->lt = SliceColumns(tb->lt, sun.nw, ws);
  }
  return b;
}

// Bilinear in (radius, sun zenith). The table blends the logarithm where the four nodes differ by
// more than 2 % and are all lit: the transmittance is exponential in both (e^-tau, tau growing by
// ~4 per km of descent through the hazed sky's aerosol with the sun 5 deg high), and a linear
// blend of e^-tau between nodes a few hundred metres apart overestimates it (the exact single
// scattering at 87 deg view zenith, sun 85 deg: +7.6 % against the path tracer's first order,
// +1.4 % with the logarithm and the nodes that follow the optical depth; docs/sky-methods.md "Sun
// transmittance"). Where the nodes agree within 2 % the linear blend is within 3e-5 of the
// logarithmic one and costs no exp; where one node is in the Earth's full shadow (0) the blend
// stays linear.
void SunTables::TransmittanceAt(const Lerp& lr, double mu_s, bool scaled, float* out) const {
  const SunTable& tb = scaled ? star : plain;
  const Lerp lt = Locate(theta_loc, std::acos(std::clamp(mu_s, -1.0, 1.0)) / kDeg);
  const size_t nt = theta_deg.size();
  const size_t n00 = lr.i * nt + lt.i, n10 = (lr.i + 1) * nt + lt.i;
  const float* p00 = &tb.t[n00 * nw];
  const float* p01 = &tb.t[(n00 + 1) * nw];
  const float* p10 = &tb.t[n10 * nw];
  const float* p11 = &tb.t[(n10 + 1) * nw];
  const float a = static_cast<float>(lr.t), b = static_cast<float>(lt.t);
  const float w00 = (1 - a) * (1 - b), w01 = (1 - a) * b, w10 = a * (1 - b), w11 = a * b;
  if (tb.pos[n00] && tb.pos[n00 + 1] && tb.pos[n10] && tb.pos[n10 + 1]) {
    // The shortest wavelength varies most (Rayleigh): it decides.
    const float* f = tb.first.data();
    const float lo = std::min(std::min(f[n00], f[n00 + 1]), std::min(f[n10], f[n10 + 1]));
    const float hi = std::max(std::max(f[n00], f[n00 + 1]), std::max(f[n10], f[n10 + 1]));
    if (hi > 1.02f * lo) {
      const float* l00 = &tb.lt[n00 * nw];
      const float* l01 = &tb.lt[(n00 + 1) * nw];
      const float* l10 = &tb.lt[n10 * nw];
      const float* l11 = &tb.lt[(n10 + 1) * nw];
      for (size_t w = 0; w < nw; ++w) out[w] = ExpF(w00 * l00[w] + w01 * l01[w] + w10 * l10[w] + w11 * l11[w]);
      return;
    }
  }
  for (size_t w = 0; w < nw; ++w) out[w] = w00 * p00[w] + w01 * p01[w] + w10 * p10[w] + w11 * p11[w];
}

}  // namespace skybake::orders
