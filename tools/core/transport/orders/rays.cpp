#include "transport/orders/rays.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "atmosphere/ray_sphere.h"

namespace skybake::orders {

namespace {

// Optical depths on a table ray's fine uniform sub-grid of nf pieces over its length d: cum at the
// reference wavelength (the step placement's), cum_w at every wavelength, and the placement
// parameter s at the fine nodes.
struct FineDepth {
  int nf = 0;
  double d = 0.0;
  std::vector<double> cum;
  std::vector<std::vector<float>> cum_w;
  std::vector<double> s_at;

  // t at placement parameter sv (s_at inverted).
  double TOfS(double sv) const {
    const Lerp l = Locate(s_at, sv);
    return (static_cast<double>(l.i) + l.t) * d / nf;
  }
  // Position of t on the fine sub-grid: the piece and the fraction into it.
  Lerp FineAt(double tv) const {
    const double pf = std::clamp(tv / d * nf, 0.0, static_cast<double>(nf));
    const size_t pi = std::min(static_cast<size_t>(pf), static_cast<size_t>(nf) - 1);
    return Lerp{pi, pf - static_cast<double>(pi)};
  }
  double TauAt(double tv, size_t w) const {
    const Lerp l = FineAt(tv);
    return cum_w[l.i][w] + (cum_w[l.i + 1][w] - cum_w[l.i][w]) * l.t;
  }
};

// The optical depths of the ray from r along mu, length d, and its placement parameter. The
// optical-depth part of s saturates at tau_cap: light from deeper than that does not reach the
// ray's start (e^-12 = 6e-6), and a ray along the inside of a thick layer (a horizontal ray in a
// 1 km cloud of optical depth 8 runs through tau ~ 900) would otherwise spread its steps over
// optical depths that contribute nothing.
FineDepth FineDepthAlong(const AtmosphereModel& m, const Medium& md, const OrdersSettings& s, double r, double mu, double d,
                         std::vector<float>* st) {
  const size_t nw = md.nw;
  const double R = m.bottom_radius_m;
  FineDepth fd;
  const int nf = s.fine;
  fd.nf = nf;
  fd.d = d;
  fd.cum.assign(static_cast<size_t>(nf) + 1, 0.0);
  fd.cum_w.assign(static_cast<size_t>(nf) + 1, std::vector<float>(nw, 0.0f));
  const size_t wref = md.wref;
  for (int p = 0; p < nf; ++p) {
    const double tm = (p + 0.5) * d / nf;
    const double rr = RadiusAt(r, mu, tm);
    md.SigmaT(rr - R, true, st->data());
    fd.cum[static_cast<size_t>(p) + 1] = fd.cum[static_cast<size_t>(p)] + (*st)[wref] * d / nf;
    for (size_t w = 0; w < nw; ++w) {
      fd.cum_w[static_cast<size_t>(p) + 1][w] = fd.cum_w[static_cast<size_t>(p)][w] + (*st)[w] * static_cast<float>(d / nf);
    }
  }
  const double tau_cap = s.tau_cap;
  const double tau_total = std::max(std::min(fd.cum.back(), tau_cap), 1e-12);
  fd.s_at.resize(static_cast<size_t>(nf) + 1);
  for (int p = 0; p <= nf; ++p) {
    fd.s_at[static_cast<size_t>(p)] = 0.5 * (std::min(fd.cum[static_cast<size_t>(p)], tau_cap) / tau_total + static_cast<double>(p) / nf);
  }
  return fd;
}

// The point of step [t0, t1] where its sources are taken. Exponential integration (the step's
// medium taken as uniform): int_t0^t1 T* dt = T*(t0) dt (1 - e^-dtau)/dtau, whose centroid is at
// optical depth tau0 + g dtau, g = 1/dtau - 1/(e^dtau - 1) at the reference wavelength (the
// midpoint for a thin step, near t0 for a thick one; the midpoint rule with T*(t_mid) loses 0.7 %
// of a step of optical depth 0.4 and everything of a step of 45). The point is where that optical
// depth is reached, whatever the medium's shape within the step (the weight is e^-tau dtau in
// optical depth): inside the medium, never in the clear air of a step that straddles a cloud's
// edge (docs/sky-methods.md "Step weights").
double StepPoint(const FineDepth& fd, double t0, double t1, size_t wref) {
  const double h = t1 - t0;
  const double a = fd.TauAt(t1, wref) - fd.TauAt(t0, wref);
  const double g = a < 1e-3 ? 0.5 - a / 12.0 : 1.0 / a - 1.0 / std::expm1(a);
  double tm = t0 + h * g;
  if (a >= 1e-3) {
    const Lerp l0 = fd.FineAt(t0);
    const double tau0 = fd.cum[l0.i] + (fd.cum[l0.i + 1] - fd.cum[l0.i]) * l0.t;
    const Lerp l = Locate(fd.cum, tau0 + g * a);
    tm = std::clamp((static_cast<double>(l.i) + l.t) * fd.d / fd.nf, t0, t1);
  }
  return tm;
}

// Step m of the family from (r, mu): its point, local geometry, sigma_s* and weight of J. The
// weight: int T* sigma_s* dt taken as sigma_s*/sigma_t* at the point times the exact
// int T* sigma_t* dt = T*(t0) (1 - e^-dtau), so that the weights of a lossless medium sum to
// 1 - T*(end) (energy is conserved: weighting sigma_s* at a point denser than the step's mean by
// the exact int T* dt scatters more than the step can, and a thick cloud's orders then grow
// without end; docs/sky-methods.md "Step weights"); where the step is optically empty, T*(t0) h.
void AddStep(const AtmosphereModel& m, const Medium& md, const Nodes& nodes, const FineDepth& fd, double r, double mu, size_t step,
             size_t nt, std::vector<float>* st, std::vector<float>* sc, Family* f) {
  const size_t nw = md.nw, wref = md.wref;
  const double R = m.bottom_radius_m;
  const double t0 = fd.TOfS(static_cast<double>(step) / nt), t1 = fd.TOfS(static_cast<double>(step + 1) / nt);
  const double h = t1 - t0;
  const double tm = StepPoint(fd, t0, t1, wref);
  f->t.push_back(tm);
  const double rr = RadiusAt(r, mu, tm);
  f->r.push_back(rr);
  f->mu.push_back(MuAt(r, mu, tm, rr));
  f->rv.push_back(nodes.RadialViewAt(rr, f->mu.back()));
  const AtmosphereModel::Cell cell = m.Locate(rr - R);  // one lookup for the step's media
  for (size_t c = 0; c < md.nc; ++c) {
    md.SigmaS(c, cell, true, sc->data());
    for (size_t w = 0; w < nw; ++w) f->ssc[step * nw + w] += (*sc)[w];
  }
  md.SigmaT(cell, true, st->data());
  for (size_t w = 0; w < nw; ++w) {
    const double tau0 = fd.TauAt(t0, w), dtau = std::max(0.0, fd.TauAt(t1, w) - tau0);
    if (dtau > 1e-6 && (*st)[w] > 0.0f) {
      f->wt[step * nw + w] = static_cast<float>(-std::exp(-tau0) * std::expm1(-dtau) / (*st)[w]);
    } else {
      const double phi = dtau > 1e-6 ? -std::expm1(-dtau) / dtau : 1.0 - 0.5 * dtau;
      f->wt[step * nw + w] = static_cast<float>(std::exp(-tau0) * h * phi);
    }
  }
}

void BuildFamily(const AtmosphereModel& m, const Medium& md, const Nodes& nodes, const OrdersSettings& s, size_t ri, size_t k,
                 std::vector<float>* st, std::vector<float>* sc, Family* f) {
  const size_t nw = md.nw, nt = static_cast<size_t>(s.nt), nr = nodes.radius.size();
  const double R = m.bottom_radius_m, top = m.top_radius_m;
  const double r = nodes.radius[ri], mu = nodes.ViewMu(k, r);
  f->ground = RayIntersectsGround(r, mu, R);
  f->d = DistanceToNearestBoundary(r, mu, R, top, f->ground);
  if (f->d <= 0.0) {  // on the ground looking down: nothing but the ground
    f->d = 0.0;
    f->trans_end.assign(nw, 1.0f);
    return;
  }
  const FineDepth fd = FineDepthAlong(m, md, s, r, mu, f->d, st);
  f->wt.resize(nt * nw);
  f->ssc.assign(nt * nw, 0.0f);
  for (size_t step = 0; step < nt; ++step) AddStep(m, md, nodes, fd, r, mu, step, nt, st, sc, f);
  f->trans_end.resize(nw);
  for (size_t w = 0; w < nw; ++w) f->trans_end[w] = std::exp(-fd.cum_w.back()[w]);
  f->g.resize(nt * nw);
  for (size_t i = 0; i < nt * nw; ++i) f->g[i] = f->wt[i] * f->ssc[i];
  for (const RadialView& v : f->rv) {
    Family::Corners c{};
    for (int dr = 0; dr < 2; ++dr) {
      const size_t rn = std::min(v.ri + static_cast<size_t>(dr), nr - 1);
      for (int dk = 0; dk < 2; ++dk) {
        const size_t kk = dk ? v.k1[dr] : v.k0[dr];
        c.off[2 * dr + dk] = static_cast<uint32_t>(nodes.Cell(rn, 0, kk, 0));
        c.w[2 * dr + dk] = static_cast<float>(v.wr[dr] * (dk ? v.tk[dr] : 1.0 - v.tk[dr]));
      }
    }
    f->rc.push_back(c);
  }
}

}  // namespace

std::vector<Family> BuildFamilies(const AtmosphereModel& m, const Medium& md, const Nodes& nodes, const OrdersSettings& s) {
  const size_t nr = nodes.radius.size(), nu = nodes.nu;
  std::vector<Family> fam(nr * nu);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nu, 1), [&](const tbb::blocked_range<size_t>& rg) {
    std::vector<float> st(md.nw), sc(md.nw);
    for (size_t idx = rg.begin(); idx != rg.end(); ++idx) BuildFamily(m, md, nodes, s, idx / nu, idx % nu, &st, &sc, &fam[idx]);
  });
  return fam;
}

SunAzimuth StepSunAzimuth(const Nodes& nodes, bool even, const Family& f, size_t m, double r, double cos_ts, double nu) {
  const double mus = ClampCosine(SunMuAt(r, cos_ts, nu, f.t[m], f.r[m]));
  const double mu2 = f.mu[m];
  const double denom = std::sqrt(std::max(1e-12, (1.0 - mu2 * mu2) * (1.0 - mus * mus)));
  return nodes.SunAzimuthAt(std::acos(mus), (nu - mu2 * mus) / denom, even);
}

}  // namespace skybake::orders
