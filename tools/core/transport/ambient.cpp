#include "transport/ambient.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace skybake {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kGauss = 16;

// 16-point Gauss-Legendre on [0, 1]: x = (1 +- x_i)/2, w = w_i/2 for the 8 positive nodes x_i
// and weights w_i of the rule on [-1, 1] (Abramowitz & Stegun, Table 25.4, n = 16).
struct Gauss16 {
  double x[kGauss], w[kGauss];
  Gauss16() {
    static const double kX[8] = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274, 0.6178762444026438,
                                 0.7554044083550030, 0.8656312023878318, 0.9445750230732326, 0.9894009349916499};
    static const double kW[8] = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025, 0.1495959888165767,
                                 0.1246289712555339, 0.0951585116824928, 0.0622535239386479, 0.0271524594117541};
    for (int k = 0; k < kGauss; ++k) {
      x[k] = 0.5 + 0.5 * (k < 8 ? -kX[7 - k] : kX[k - 8]);
      w[k] = 0.5 * (k < 8 ? kW[7 - k] : kW[k - 8]);
    }
  }
};

// One quadrature part: directions and their weights (mu dw times the split weight, both mirror
// halves).
struct Part {
  std::vector<std::array<double, 3>> dirs;
  std::vector<double> wt;
};

}  // namespace

std::vector<double> AmbientIrradiance(const SkyMethod& method, double observer_altitude_m, double sun_zenith_rad,
                                      const AmbientQuadrature& q) {
  static const Gauss16 g;
  const double ts = sun_zenith_rad;
  const bool cap = q.sun_cap && std::cos(ts) > 0.0 && q.cap_deg > 0.0 && q.cap_psi > 0;
  const double t1 = q.cap_flat_deg * kPi / 180.0, t2 = std::max(q.cap_deg * kPi / 180.0, t1);
  // The split weight at angle th from the sun.
  auto W = [&](double th) {
    if (th <= t1) return 1.0;
    if (th >= t2) return 0.0;
    return 0.5 * (1.0 + std::cos(kPi * (th - t1) / (t2 - t1)));
  };
  const std::array<double, 3> s{std::sin(ts), 0.0, std::cos(ts)};
  std::vector<Part> parts;
  // The grid: one part per ring of constant mu.
  constexpr int kPhi = 32;
  for (int k = 0; k < kGauss; ++k) {
    Part p;
    const double mu = g.x[k];
    const double st = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    for (int j = 0; j < kPhi; ++j) {
      const double phi = kPi * (j + 0.5) / kPhi;
      const std::array<double, 3> d{st * std::cos(phi), st * std::sin(phi), mu};
      double wt = 2.0 * g.w[k] * mu * kPi / kPhi;
      if (cap) wt *= 1.0 - W(std::acos(std::clamp(d[0] * s[0] + d[2] * s[2], -1.0, 1.0)));
      if (wt == 0.0) continue;
      p.dirs.push_back(d);
      p.wt.push_back(wt);
    }
    parts.push_back(std::move(p));
  }
  // The cap: one part per azimuth psi around the sun. d = cos(Th) s + sin(Th) (cos(psi) t + sin(psi) b)
  // with t = (cos ts, 0, -sin ts) (from the sun towards the horizon below it) and b = +y; its
  // mu = cos(Th) cos(ts) - sin(Th) cos(psi) sin(ts) reaches 0 at Th_h = atan2(cos ts, cos(psi) sin ts).
  // Theta = end u^2 for u in [0, 1], end = the cap's radius or Th_h.
  const std::array<double, 3> t{std::cos(ts), 0.0, -std::sin(ts)};
  auto cap_end = [&](double psi) { return std::min(t2, std::atan2(std::cos(ts), std::cos(psi) * std::sin(ts))); };
  auto cap_dir = [&](double th, double psi) {
    std::array<double, 3> d;
    for (int i = 0; i < 3; ++i) d[i] = std::cos(th) * s[i] + std::sin(th) * (std::cos(psi) * t[i] + (i == 1 ? std::sin(psi) : 0.0));
    return d;
  };
  // mu dw W for the cap's point at u on [0, 1] (quadrature weight du) and azimuth weight dpsi.
  auto cap_weight = [&](double end, double u, double du, double dpsi, double th, double mu) {
    return 2.0 * du * (2.0 * end * u) * std::sin(th) * dpsi * mu * W(th);
  };
  if (cap) {
    for (int j = 0; j < q.cap_psi; ++j) {
      Part p;
      const double psi = kPi * (j + 0.5) / q.cap_psi, end = cap_end(psi);
      for (int k = 0; k < kGauss; ++k) {
        const double th = end * g.x[k] * g.x[k];
        const std::array<double, 3> d = cap_dir(th, psi);
        if (d[2] <= 0.0) continue;
        p.dirs.push_back(d);
        p.wt.push_back(cap_weight(end, g.x[k], g.w[k], kPi / q.cap_psi, th, d[2]));
      }
      parts.push_back(std::move(p));
    }
  }
  // Each part's weights scaled so that they integrate mu exactly: the cap's to int W mu dw, the
  // grid's to pi - that (a uniform sky is then exact; unscaled, the grid's 16 rings resolve the
  // raised cosine of 1 - W only to ~5e-4 with the sun at the zenith, where it runs along mu).
  // int W mu dw by a dense midpoint rule of the cap's own form (no radiance: a few ms).
  if (cap) {
    double exact = 0.0;
    constexpr int kPsi = 64, kV = 256;
    for (int j = 0; j < kPsi; ++j) {
      const double psi = kPi * (j + 0.5) / kPsi, end = cap_end(psi);
      for (int k = 0; k < kV; ++k) {
        const double v = (k + 0.5) / kV, th = end * v * v;
        exact += cap_weight(end, v, 1.0 / kV, kPi / kPsi, th, std::max(0.0, cap_dir(th, psi)[2]));
      }
    }
    double sum_grid = 0.0, sum_cap = 0.0;
    for (size_t i = 0; i < parts.size(); ++i) {
      for (double w : parts[i].wt) (i < kGauss ? sum_grid : sum_cap) += w;
    }
    for (size_t i = 0; i < parts.size(); ++i) {
      const double f = i < kGauss ? (kPi - exact) / sum_grid : (sum_cap > 0.0 ? exact / sum_cap : 0.0);
      for (double& w : parts[i].wt) w *= f;
    }
  }
  // The grid's rings first, then the cap (a method that keeps view rays between calls sees the
  // rings, which recur at every sun angle, before the cap's, which do not).
  std::vector<std::vector<double>> L(parts.size());
  auto render = [&](size_t i) {
    if (!parts[i].dirs.empty()) method.Radiance(observer_altitude_m, ts, parts[i].dirs, &L[i]);
  };
  tbb::parallel_for(size_t{0}, size_t{kGauss}, render);
  tbb::parallel_for(size_t{kGauss}, parts.size(), render);
  std::vector<double> E;
  for (size_t i = 0; i < parts.size(); ++i) {
    const Part& p = parts[i];
    if (p.dirs.empty()) continue;
    const size_t nw = L[i].size() / p.dirs.size();
    if (E.empty()) E.assign(nw, 0.0);
    for (size_t d = 0; d < p.dirs.size(); ++d) {
      for (size_t w = 0; w < nw; ++w) E[w] += p.wt[d] * L[i][d * nw + w];
    }
  }
  return E;
}

}  // namespace skybake
