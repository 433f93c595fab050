#include "transport/orders/solve.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "transport/orders/acceleration.h"
#include "transport/orders/kernel.h"
#include "transport/orders/transport.h"

namespace skybake::orders {

namespace {

// Order 1 of the scaled problem at every cell into L: the sun's light scattered once along each
// table ray (P*, T* from the scaled sun table) and the ground's reflection of the direct sun;
// fills tc->sun_az (the radius nodes it stores) on the way.
void FirstOrder(const AtmosphereModel& m, const Medium& md, const SunTables& sun, TransportContext* tc, Table* L) {
  const Nodes& nodes = *tc->nodes;
  const size_t nw = md.nw, nc = md.nc, ns = nodes.ns, nu = nodes.nu, nr = nodes.radius.size();
  const size_t nphi = static_cast<size_t>(nodes.nphi);
  const double R = m.bottom_radius_m;
  std::vector<float> E0(ns * nw);  // direct sun at the ground (scaled transmittance)
  {
    std::vector<float> tr(nw);
    for (size_t si = 0; si < ns; ++si) {
      const double mus = std::cos(nodes.sun_theta_rad[si]);
      sun.Transmittance(R, mus, true, tr.data());
      for (size_t w = 0; w < nw; ++w) E0[si * nw + w] = static_cast<float>(md.sun_e[w] * std::max(0.0, mus)) * tr[w];
    }
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * ns * nu, 4), [&](const tbb::blocked_range<size_t>& rg) {
    std::vector<float> tsun(nw), src(nw), acc(nw), pc(nc * nw), eg(nw), ssc;
    for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
      const size_t ri = idx / (ns * nu), si = (idx / nu) % ns, k = idx % nu;
      const Family& f = (*tc->fam)[ri * nu + k];
      const double r = nodes.radius[ri], ts = nodes.sun_theta_rad[si];
      // sigma_s* of every component at the family's steps, the same for all its azimuths.
      ssc.resize(f.t.size() * nc * nw);
      for (size_t st = 0; st < f.t.size(); ++st) {
        const AtmosphereModel::Cell cm = m.Locate(f.r[st] - R);
        for (size_t c = 0; c < nc; ++c) md.SigmaS(c, cm, true, &ssc[(st * nc + c) * nw]);
      }
      for (size_t q = 0; q < nphi; ++q) {
        double mu, nu_s;
        nodes.CellGeometry(ri, si, k, q, &mu, &nu_s);
        for (size_t c = 0; c < nc; ++c) {
          for (size_t w = 0; w < nw; ++w) pc[c * nw + w] = md.PhaseStar(c, nu_s, w);
        }
        std::fill(acc.begin(), acc.end(), 0.0f);
        for (size_t st = 0; st < f.t.size(); ++st) {
          const double mus = (r * tc->cos_sun[si] + f.t[st] * nu_s) / f.r[st];
          sun.Transmittance(f.r[st], mus, true, tsun.data());
          std::fill(src.begin(), src.end(), 0.0f);
          for (size_t c = 0; c < nc; ++c) {
            const float* sv = &ssc[(st * nc + c) * nw];
            for (size_t w = 0; w < nw; ++w) src[w] += sv[w] * pc[c * nw + w];
          }
          for (size_t w = 0; w < nw; ++w) acc[w] += f.wt[st * nw + w] * src[w] * tsun[w] * static_cast<float>(md.sun_e[w]);
          if (tc->Stored(ri)) {
            tc->sun_az[tc->PositionIndex(ri, k, st, si, q)] =
                PackSunAzimuth(StepSunAzimuth(nodes, tc->s->azimuth_even, f, st, r, tc->cos_sun[si], nu_s));
          }
        }
        if (f.ground) AddGroundReflection(nodes, md, f, r, ts, nu_s, E0, eg.data(), acc.data());
        std::copy(acc.begin(), acc.end(), &(*L)[nodes.Cell(ri, si, k, q) * nw]);
      }
    }
  });
}

// The per-element ratio L_{n-1} / L_{n-2} that the tail's test needs (AddTail), one byte per
// element instead of the table L_{n-2} itself (a quarter of a table: 23 MB instead of 93 MB for
// high's daylight part): kRatioNone where the ratio is not below 1 or L_{n-2} is not positive
// (the test fails there whatever L_n), else floor(254 r), read back as the bin's centre (c +
// 1/2) / 254, within 1/508 of r. The test compares it with L_n / L_{n-1} at a threshold of 0.05,
// so only an element within 0.002 of that threshold can take the other of its two acceptable
// ratios (its own or the observer's).
constexpr uint8_t kRatioNone = 255;
inline uint8_t RatioCode(float now, float before) {
  if (!(before > 0.0f)) return kRatioNone;
  const double r = now / static_cast<double>(before);
  if (!(r < 1.0)) return kRatioNone;
  return static_cast<uint8_t>(std::min(253.0, std::floor(std::max(0.0, r) * 254.0)));
}
inline double RatioOfCode(uint8_t c) { return (c + 0.5) / 254.0; }

// The tables of the iteration; J the sources of order n. With kept sources (view segments read
// J_ms at every node, and the tail of J_ms needs every element's orders): L = L_{n-1} while
// order n is computed into Lnext, and ratio the code of L_{n-1} / L_{n-2} per element. Without
// (a sky reads the observer's radius alone): order n is transported into L in place - the
// transport reads L_{n-1} only for the ground's irradiance, which it forms first - so the solve
// holds two fields instead of three ("Peak memory" in docs/sky-methods.md); the observer's slab
// of L_{n-1} is kept in prev_obs and ratio holds the observer's codes alone. The two forms
// compute the same values.
struct OrderTables {
  bool in_place = false;
  Table L, J, Lnext;
  std::vector<uint8_t> ratio;
  std::vector<float> prev_obs;  // in place: the observer's L_{n-1}
};

// The observer radius's elements (ns x nd x nw from `offset`) of L_{n-1}, L_n and the codes of
// L_{n-1} / L_{n-2}, in either form of the tables.
struct ObserverOrders {
  const float* before;
  const float* now;
  const uint8_t* code;
};
ObserverOrders Observer(const OrderTables& t, size_t offset) {
  if (t.in_place) return {t.prev_obs.data(), t.L.data() + offset, t.ratio.data()};
  return {t.L.data() + offset, t.Lnext.data() + offset, t.ratio.data() + offset};
}

// The ratio history of the stopping rule (norms of successive orders at the observer, reference
// wavelength; and every wavelength's norm of the last order, for the dominant-mode tail).
struct RatioHistory {
  double prev_norm = 0.0, prev_ratio = -1.0, prev_prev_ratio = -1.0;
  std::vector<double> prev_norm_w;
};

// The error of the geometric tail from the ratio's last two changes, fraction_n d_rho /
// (1 - rho)^2 of the total (TakeTail); ratio settled (in (0, 1), with a ratio before it).
double RatioTailError(double fraction, double ratio, const RatioHistory& h) {
  const double d_rho = std::max(std::abs(ratio - h.prev_ratio), h.prev_prev_ratio > 0.0 ? std::abs(h.prev_ratio - h.prev_prev_ratio) : 1.0);
  return fraction * d_rho / ((1.0 - ratio) * (1.0 - ratio));
}

// Geometric tail once the ratio of successive orders has settled: the remaining orders sum to
// L_n rho / (1 - rho), and an error d_rho in rho changes that by about fraction_n d_rho /
// (1 - rho)^2 of the total; stop when that is below the tolerance. d_rho is the larger of the
// last two changes of the ratio: with one, a ratio passing an extremum looks settled (the hazed
// sky's ratios 0.521, 0.503, 0.503 at orders 3-5, going on to 0.52 by order 12, would take the
// tail at order 5: 2.2 % RMS at sun 70 deg instead of 0.6 %).
//  - A tail of at most tail_share_max (10 %) of the total is taken early, per element
//    (kPerElement): a thin sky's tail comes while its elements still decay at their own rates.
//    The share limit: in a thick layer the ratio settles while modes other than the dominant one
//    still matter, which the test on d_rho does not see (cloudy5 at high: the ratio settles to
//    1e-5 by order 28, yet the dominant-mode tail taken there is 0.6 % RMS, max -0.9 %, off
//    the sky of 100 orders at sun 70 deg; at order 25 1.2 %, max -1.8 %; bench_orders_tail).
//    A larger tail is taken with the next mode as well (kTwoModes, SecondMode), decided in the
//    solve's loop.
//  - At the last allowed order, if the ratio has settled at all, the dominant mode's tail
//    (kDominant): every element at its wavelength's observer ratio. After many orders every
//    element decays at the dominant eigenvalue of its wavelength's kernel (the orders do not mix
//    wavelengths), while element ratios are still drifting towards it: under cloudy5's deck at
//    order 25 a per-element tail is 7.6 % RMS off the sky of 59 orders and their tail at sun 70 deg
//    (a tail of 87 % at worst from elements whose ratio is near 1), the dominant mode's 1.2 %.
//    The eigenvalue differs between wavelengths (cloudy5: 0.955 at 600 nm, 0.973 at 780 nm), so
//    the reference wavelength's ratio would put the wrong tail on the others.
Tail TakeTail(const OrdersSettings& s, int order, double fraction, double ratio, const RatioHistory& h) {
  const bool settled = ratio > 0.0 && ratio < 1.0 && h.prev_ratio > 0.0;
  if (!settled) return Tail::kNone;
  const double tail_error = RatioTailError(fraction, ratio, h);
  const double tail_share = fraction * ratio / (1.0 - ratio);
  if (s.early_tail && order >= 5 && tail_error < s.tolerance && tail_share <= s.tail_share_max) return Tail::kPerElement;
  if (order == s.max_orders && std::abs(ratio - h.prev_ratio) < 0.02) return Tail::kDominant;
  return Tail::kNone;
}

// Adds the geometric tail sum_{k>n} L_k ~ L_n rho / (1 - rho) to ms and jms; the sources J_n
// decay like the radiances of their node. rho is capped at rho_cap (0.98: tail <= 49 L_n).
//  - kDominant: rho = ratio_w[w], the observer's ratio at the element's wavelength (TakeTail).
//  - kPerElement: rho per table element (the horizon and the shadowed sky decay more slowly than
//    the observer's average: with one global rho the hazed horizon misses 0.55 % at tolerance
//    1e-3, within 0.3 % per element; tests/transport/method_orders_test.cpp): the element's
//    L_n / L_{n-1} where that and L_{n-1} / L_{n-2} agree within 0.05 and are below 1, the
//    observer's ratio at the reference wavelength elsewhere (an element whose orders still grow -
//    the low-sun horizon's at order 4 - would get a tail of 9 L_n from its own ratio and come out
//    60 % bright).
// Per element the factor rho / (1 - rho) of its L_n, from L_{n-1} (before), L_n (now) and the
// code of L_{n-1} / L_{n-2}; the jms part (kept sources only) reads every element of L, Lnext and
// ratio.
void AddTail(const Nodes& nodes, const OrdersSettings& s, size_t nd, Tail kind, double ratio, const std::vector<double>& ratio_w,
             const OrderTables& t, SolveResult* out) {
  const size_t nw = nodes.nw, n = nodes.ns * nd * nw;
  std::vector<float> dominant(nw);
  for (size_t w = 0; w < nw; ++w) {
    const double rho = std::clamp(ratio_w[w], 0.0, s.rho_cap);
    dominant[w] = static_cast<float>(rho / (1.0 - rho));
  }
  auto factor = [&](size_t w, float before, float now, uint8_t c0) {
    if (kind == Tail::kDominant) return dominant[w];
    const double r1 = before > 0.0f ? now / static_cast<double>(before) : 2.0;
    double rho = r1 < 1.0 && c0 != kRatioNone && std::abs(r1 - RatioOfCode(c0)) < 0.05 ? r1 : ratio;
    rho = std::clamp(rho, 0.0, s.rho_cap);
    return static_cast<float>(rho / (1.0 - rho));
  };
  // ms[j] is the observer's element j (the slab's layout: [(si * nd + i) * nw + w]).
  const ObserverOrders o = Observer(t, nodes.obs_index * n);
  for (size_t j = 0; j < n; ++j) out->ms[j] += factor(j % nw, o.before[j], o.now[j], o.code[j]) * o.now[j];
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out->jms.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
    for (size_t i = rg.begin(); i != rg.end(); ++i) out->jms[i] += factor(i % nw, t.L[i], t.Lnext[i], t.ratio[i]) * t.J[i];
  });
  out->tail = kind;
}

// The second mode of a thick sky's series. With the dominant ratio lambda (per wavelength, at the
// observer) the differences D_n = L_n - lambda L_{n-1} hold what is not the dominant mode; once
// they too decay geometrically, at mu, the remaining orders sum to
//   sum_{k>n} L_k = L_n lambda / (1 - lambda) + D_n mu / ((1 - mu) (1 - lambda))
// (the dominant mode's tail plus the sum of the next mode's part of the orders: sum_{k>n} D_k /
// (1 - lambda)). mu per wavelength is sum |D_n| / sum |D_{n-1}| over the observer's elements, both
// with the same lambda (the observer's L_{n-2} is kept for it: a small table). Under cloudy5's
// deck mu settles at 0.755-0.76 against lambda 0.955 (600 nm), and the tail taken at order 28 is
// within 0.08 % RMS, max -0.10 %, of 100 orders at sun 30-85 deg, against 0.6 % RMS for the
// dominant mode's alone (bench_orders_tail).
struct SecondMode {
  std::vector<double> lambda, mu;  // per wavelength
  double fraction = 1.0;           // sum |D_n| / ((1 - lambda) total) at the reference wavelength
};
SecondMode EstimateSecondMode(const Nodes& nodes, size_t nd, size_t wref, double ratio, const std::vector<double>& lambda,
                              const ObserverOrders& o, const std::vector<float>& obs_before, double total) {
  const size_t nw = nodes.nw, n = nodes.ns * nd * nw;
  SecondMode m;
  m.lambda = lambda;
  std::vector<double> dn(nw, 0.0), dm(nw, 0.0);
  for (size_t j = 0; j < n; ++j) {
    const size_t w = j % nw;
    dn[w] += std::abs(o.now[j] - m.lambda[w] * o.before[j]);
    dm[w] += std::abs(o.before[j] - m.lambda[w] * obs_before[j]);
  }
  m.mu.resize(nw);
  for (size_t w = 0; w < nw; ++w) m.mu[w] = dm[w] > 0.0 ? dn[w] / dm[w] : 0.0;
  if (total > 0.0 && ratio < 1.0) m.fraction = dn[wref] / ((1.0 - ratio) * total);
  return m;
}

// Adds the two modes' tail (SecondMode) to ms and, through one more scattering step, to jms (if kept):
// sum_{k>n} J_k = Scatter(sum_{k>=n} L_k), the sources of the radiance's remaining orders. An
// element's tail is kept non-negative. L is overwritten (it holds L_n + the tail for the step).
void AddTwoModeTail(const KernelContext& kc, const ScatterKernels& sk, const Nodes& nodes, const OrdersSettings& s, size_t nd,
                    const SecondMode& sm, OrderTables* t, SolveResult* out) {
  const size_t nw = nodes.nw, ns = nodes.ns;
  std::vector<float> a(nw), b(nw), lf(nw);
  for (size_t w = 0; w < nw; ++w) {
    const double l = std::clamp(sm.lambda[w], 0.0, s.rho_cap), m = std::clamp(sm.mu[w], 0.0, l);
    a[w] = static_cast<float>(l / (1.0 - l));
    b[w] = static_cast<float>(m / ((1.0 - m) * (1.0 - l)));
    lf[w] = static_cast<float>(l);
  }
  auto tail = [&](size_t w, float before, float now) { return std::max(now * a[w] + (now - lf[w] * before) * b[w], 0.0f); };
  const size_t n = ns * nd * nw;
  const ObserverOrders o = Observer(*t, nodes.obs_index * n);
  for (size_t j = 0; j < n; ++j) out->ms[j] += tail(j % nw, o.before[j], o.now[j]);
  out->tail = Tail::kTwoModes;
  if (out->jms.empty()) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, t->L.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
    for (size_t i = rg.begin(); i != rg.end(); ++i) t->L[i] = t->Lnext[i] + tail(i % nw, t->L[i], t->Lnext[i]);
  });
  Scatter(kc, sk, t->L, &t->J);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out->jms.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
    for (size_t i = rg.begin(); i != rg.end(); ++i) out->jms[i] += t->J[i];
  });
}

// Whether the two modes' tail may be considered: the tail too large a share for the early
// per-element one (TakeTail) and the ratio settled, from order 5.
bool TwoModesApply(const OrdersSettings& s, int order, double fraction, double ratio, const RatioHistory& h) {
  return s.early_tail && order >= 5 && ratio > 0.0 && ratio < 1.0 && h.prev_ratio > 0.0 && h.prev_prev_ratio > 0.0 &&
         fraction * ratio / (1.0 - ratio) > s.tail_share_max;
}

// Whether to stop with it: the dominant ratio settled to the tolerance (RatioTailError), mu below
// it by 0.02 at least and settled so that its error moves the next mode's part by less than the
// tolerance (fraction_D |d_mu| / (1 - mu)^2).
bool TakeTwoModes(const OrdersSettings& s, double fraction, double ratio, const RatioHistory& h, double mu, double prev_mu,
                  double d_fraction) {
  if (!(mu > 0.0 && mu < ratio - 0.02 && prev_mu > 0.0)) return false;
  const double mu_error = d_fraction * std::abs(mu - prev_mu) / ((1.0 - mu) * (1.0 - mu));
  return RatioTailError(fraction, ratio, h) < s.tolerance && mu_error < s.tolerance;
}

// Adds L (order n) at the observer radius to ms; returns its norm at the reference wavelength
// wref, sets *total to the accumulated one and norm_w to the norm at every wavelength. The norm is
// the sum of the elements, or of their magnitudes (`magnitude`: an accelerated series, whose
// increments change sign where a correction overshot).
double AccumulateAtObserver(const Nodes& nodes, size_t nd, size_t wref, const Table& L, bool magnitude, std::vector<float>* ms,
                            double* total, std::vector<double>* norm_w) {
  const size_t nw = nodes.nw, ns = nodes.ns;
  double norm = 0.0;
  *total = 0.0;
  norm_w->assign(nw, 0.0);
  for (size_t si = 0; si < ns; ++si) {
    for (size_t i = 0; i < nd; ++i) {
      const float* v = &L[(((nodes.obs_index * ns + si) * nd) + i) * nw];
      float* a = &(*ms)[((si * nd) + i) * nw];
      for (size_t w = 0; w < nw; ++w) {
        a[w] += v[w];
        (*norm_w)[w] += magnitude ? std::abs(v[w]) : v[w];
      }
      norm += magnitude ? std::abs(v[wref]) : v[wref];
      *total += a[wref];
    }
  }
  return norm;
}

}  // namespace

SolveResult SolveOrders(const AtmosphereModel& m, const Medium& md, const SunTables& sun, const Nodes& nodes, const OrdersSettings& s,
                        bool keep_sources, const ProgressFn& progress) {
  const size_t nw = md.nw, nr = nodes.radius.size(), nphi = static_cast<size_t>(s.nphi);
  const size_t cells = nr * nodes.ns * nodes.nu * nphi;
  const std::vector<Family> fam = BuildFamilies(m, md, nodes, s);
  TransportContext tc = MakeTransportContext(m, md, nodes, s, fam);
  // The kernels before the tables: their build's scratch (two radii's double coefficients per
  // thread, 107 MB at 2 threads for high) is freed before the tables are touched, so it adds
  // nothing to the peak.
  const KernelContext kc = MakeKernelContext(md, nodes, s);
  const ScatterKernels sk = BuildScatterKernels(kc);
  const size_t nd = nodes.nu * nphi;                    // directions per (radius, sun)
  const size_t n_obs = nodes.ns * nd * nw, obs_offset = nodes.obs_index * n_obs;  // the observer's slab
  OrderTables t;
  t.in_place = !keep_sources;
  for (Table* x : {&t.L, &t.J}) ZeroTable(x, cells * nw);
  if (!t.in_place) ZeroTable(&t.Lnext, cells * nw);
  t.ratio.assign(t.in_place ? n_obs : cells * nw, kRatioNone);  // no L_0: the test fails at order 2
  ReportProgress(progress, "orders: order 1", 0.0);
  FirstOrder(m, md, sun, &tc, &t.L);

  SolveResult out;
  out.ms.assign(nodes.ns * nodes.nu * nphi * nw, 0.0f);
  // Diffusion synthetic acceleration under a thick column (acceleration.h); the first order's
  // correction belongs to the multiple scattering, so ms starts with it at the observer.
  out.column_depth = ScaledColumnDepth(md, nodes);
  const bool accelerate = s.dsa_from_tau > 0.0 && out.column_depth >= s.dsa_from_tau;
  DiffusionAcceleration dsa;
  out.accelerated = accelerate;
  if (accelerate) {
    dsa = MakeDiffusionAcceleration(md, nodes, kc);
    const std::vector<float> first(t.L.begin() + static_cast<std::ptrdiff_t>(obs_offset),
                                   t.L.begin() + static_cast<std::ptrdiff_t>(obs_offset + n_obs));
    Accelerate(&dsa, &t.L);
    for (size_t j = 0; j < n_obs; ++j) out.ms[j] += t.L[obs_offset + j] - first[j];
  }
  if (keep_sources) ZeroTable(&out.jms, cells * nw);
  // An accelerated series' increments are not orders (their mean sources change sign), so the
  // sun blend of its sources is linear throughout (acceleration.h has the measurements).
  if (accelerate) tc.loglin_first = nodes.ns;
  RatioHistory h;
  std::vector<double> norm_w, ratio_w(nw);
  std::vector<float> obs_before;  // the observer's L_{n-2} (SecondMode)
  double prev_mu = -1.0;
  for (int order = 2; order <= s.max_orders; ++order) {
    ReportProgress(progress, fmt::format("orders: order {}", order), 0.0);
    Scatter(kc, sk, t.L, &t.J);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, out.jms.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t i = rg.begin(); i != rg.end(); ++i) out.jms[i] += t.J[i];
    });
    if (t.in_place) {
      const auto from = t.L.begin() + static_cast<std::ptrdiff_t>(obs_offset);
      t.prev_obs.assign(from, from + static_cast<std::ptrdiff_t>(n_obs));
      Transport(tc, t.J, t.L, &t.L);
      if (accelerate) Accelerate(&dsa, &t.L);
    } else {
      Transport(tc, t.J, t.L, &t.Lnext);
      if (accelerate) Accelerate(&dsa, &t.Lnext);
    }
    const Table& now = t.in_place ? t.L : t.Lnext;  // L_n
    // Accumulate L_n at the observer radius; convergence on the reference wavelength (every
    // decision below reads it, so a wavelength batch that holds it stops as the whole does).
    double total = 0.0;
    const double norm = AccumulateAtObserver(nodes, nd, md.wref, now, accelerate, &out.ms, &total, &norm_w);
    out.orders_done = order;
    out.last_fraction = total > 0.0 ? norm / total : 0.0;
    const double ratio = h.prev_norm > 0.0 ? norm / h.prev_norm : -1.0;
    if (out.last_fraction < s.tolerance) break;
    for (size_t w = 0; w < nw; ++w) ratio_w[w] = h.prev_norm_w.empty() || !(h.prev_norm_w[w] > 0.0) ? ratio : norm_w[w] / h.prev_norm_w[w];
    const Tail tail = TakeTail(s, order, out.last_fraction, ratio, h);
    if (tail != Tail::kNone) {
      AddTail(nodes, s, nd, tail, ratio, ratio_w, t, &out);
      break;
    }
    if (!obs_before.empty() && TwoModesApply(s, order, out.last_fraction, ratio, h)) {
      const SecondMode sm = EstimateSecondMode(nodes, nd, md.wref, ratio, ratio_w, Observer(t, obs_offset), obs_before, total);
      const double mu = sm.mu[md.wref];
      if (TakeTwoModes(s, out.last_fraction, ratio, h, mu, prev_mu, sm.fraction)) {
        AddTwoModeTail(kc, sk, nodes, s, nd, sm, &t, &out);
        break;
      }
      prev_mu = mu;
    } else {
      prev_mu = -1.0;
    }
    h.prev_prev_ratio = h.prev_ratio;
    h.prev_ratio = ratio;
    h.prev_norm = norm;
    h.prev_norm_w = norm_w;
    // Next order: the ratio codes L_n / L_{n-1}, the observer's L_{n-1} as its L_{n-2}, L = L_n.
    if (t.in_place) {
      for (size_t j = 0; j < n_obs; ++j) t.ratio[j] = RatioCode(t.L[obs_offset + j], t.prev_obs[j]);
      if (order >= 3) obs_before.swap(t.prev_obs);
      continue;
    }
    if (order >= 3) {
      const auto from = t.L.begin() + static_cast<std::ptrdiff_t>(obs_offset);
      obs_before.assign(from, from + static_cast<std::ptrdiff_t>(n_obs));
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, t.ratio.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t i = rg.begin(); i != rg.end(); ++i) t.ratio[i] = RatioCode(t.Lnext[i], t.L[i]);
    });
    std::swap(t.L, t.Lnext);
  }
  return out;
}

}  // namespace skybake::orders
