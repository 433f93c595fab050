#include "transport/orders/nodes.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "atmosphere/model.h"
#include "atmosphere/ray_sphere.h"

namespace skybake::orders {

// Radius nodes uniform in s(h) = (tau(0,h)/tau(0,H) + (h/H)^0.4) / 2, tau the vertical optical
// depth at the grid's middle wavelength: the altitude part alone is h_i = H (i/(n-1))^2.5 (0, 0.12,
// 0.65, 1.8, 3.7, 6.4, 10 ... 100 km for n = 16), the optical-depth part puts half the nodes where
// the extinction is, so that a 2 km thick water cloud at 3.5-5.5 km (cloudy4) has nodes inside it
// (interpolated from outside the cloud, its sources make the sky under it 3-5x too dark).
//
// Under a thick cloud those nr nodes are not enough: the tables blend the sources J/sigma_s*
// linearly between radius nodes, and inside a cloud they change by a large factor over one
// optical depth; the blend's excess is carried through every order, so the sky under cloudy4
// comes out +12 % with 16 nodes. With radius_dtau > 0 every interval of the nr nodes that holds
// more than radius_dtau is split into pieces of equal optical depth (the nr nodes are kept, so
// the cloud-free column is resolved as in a clear sky). Equal optical depth, not equal altitude:
// cloudy4's pieces at 0.25 are 1.9 % RMS off its sky with 114 nodes, equal-altitude pieces of the
// same count 5.2 %; at the same 64 nodes the split is 0.70 % off, 64 nodes uniform in s(h)
// 1.17 % (docs/sky-methods.md "Radius nodes under a cloud").
std::vector<double> RadiusNodeAltitudes(const OrdersSettings& s, const std::function<double(double)>& tau_of, double H) {
  const double tau_total = std::max(tau_of(H), 1e-12);
  auto s_of = [&](double h) { return 0.5 * (tau_of(h) / tau_total + std::pow(h / H, 0.4)); };
  const std::vector<double> base = AltitudesUniformIn(s_of, s.nr, H);
  if (s.radius_dtau <= 0.0) return base;
  std::vector<double> tau_base(base.size()), dtau(base.size() - 1);
  for (size_t i = 0; i < base.size(); ++i) tau_base[i] = tau_of(base[i]);
  for (size_t i = 0; i + 1 < base.size(); ++i) dtau[i] = tau_base[i + 1] - tau_base[i];
  auto pieces = [&](double d, size_t i) { return std::max(1.0, std::ceil(dtau[i] / d - 1e-9)); };
  auto count = [&](double d) {
    double n = 1.0;
    for (size_t i = 0; i < dtau.size(); ++i) n += pieces(d, i);
    return n;
  };
  // The finest piece that keeps the count within radius_max: count(d) falls as d grows.
  double d = s.radius_dtau;
  if (count(d) > s.radius_max) {
    double lo = d, hi = std::max(d, tau_total);
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (count(mid) > s.radius_max ? lo : hi) = mid;
    }
    d = hi;
  }
  std::vector<double> h{base.front()};
  for (size_t i = 0; i < dtau.size(); ++i) {
    const int m = static_cast<int>(pieces(d, i));
    // The altitudes where the optical depth from base[i] is j/m of the interval's.
    for (int j = 1; j < m; ++j) h.push_back(AltitudeWhere(tau_of, tau_base[i] + dtau[i] * j / m, base[i], base[i + 1]));
    h.push_back(base[i + 1]);
  }
  return h;
}

Nodes BuildNodes(const AtmosphereModel& m, const OrdersSettings& s, double observer_altitude_m) {
  Nodes n;
  n.bottom_radius_m = m.bottom_radius_m;
  n.nup = s.nup, n.ndn = s.ndn, n.nphi = s.nphi, n.view_power = s.view_power;
  n.nw = m.wavelengths();
  const double R = m.bottom_radius_m, H = m.top_radius_m - R;
  const size_t wref = m.wavelengths() / 2;
  for (double h : RadiusNodeAltitudes(s, [&](double h) { return m.VerticalOpticalDepth(0.0, h, wref); }, H)) n.radius.push_back(R + h);
  const double r_obs = R + std::clamp(observer_altitude_m, 0.0, H * 0.999);
  auto it = std::lower_bound(n.radius.begin(), n.radius.end(), r_obs);
  if (it != n.radius.end() && std::abs(*it - r_obs) < 1e-6) {
    n.obs_index = static_cast<size_t>(it - n.radius.begin());
  } else {
    n.obs_index = static_cast<size_t>(it - n.radius.begin());
    n.radius.insert(it, r_obs);
  }
  for (double d : s.sun_deg) n.sun_theta_rad.push_back(d * kDeg);
  n.ns = n.sun_theta_rad.size();
  n.sun_loc = IntervalLocator(n.sun_theta_rad);
  n.nu = static_cast<size_t>(s.nup + s.ndn);
  return n;
}

double Nodes::HorizonMu(double r) const { return skybake::HorizonMu(r, bottom_radius_m); }

// View nodes, in ascending mu, placed in the view zenith angle theta (theta_h the horizon's,
// > 90 deg): k < ndn below the horizon, theta = theta_h + (pi - theta_h)(1 - s)^p, s = k/(ndn-1),
// from the nadir to the horizon's lower side; k >= ndn above it, theta = theta_h (1 - s^p),
// s = (k-ndn)/(nup-1), from the horizon's upper side to the zenith. Both sets include their ends
// (the horizon on each side of the discontinuity, the zenith, the nadir) and are dense next to
// the horizon (p = 2: 0.4 deg from it with 16 up nodes); integrals use the trapezoid rule in mu
// on each set. Placed in angle, not in mu, so that the zenith and the nadir have nodes near them:
// under a tau-8 cloud nodes quadratic in mu put the sky at 85 deg 22 % dark.
double Nodes::ViewMu(size_t k, double r) const {
  const bool down = k < static_cast<size_t>(ndn);
  return ViewMuAt(down, static_cast<double>(down ? k : k - static_cast<size_t>(ndn)), r);
}

double Nodes::ViewMuAt(bool down, double f, double r) const {
  const double th = std::acos(HorizonMu(r));
  const double p = view_power;
  if (down) return std::cos(th + (kPi - th) * std::pow(1.0 - f / (ndn - 1), p));
  return std::cos(th * (1.0 - std::pow(f / (nup - 1), p)));
}

double Nodes::ViewWidth(size_t k, double r) const {
  // Trapezoid weight: half the distance between the neighbours within the node's own set.
  const bool down = k < static_cast<size_t>(ndn);
  const size_t lo = down ? 0 : static_cast<size_t>(ndn);
  const size_t hi = down ? static_cast<size_t>(ndn) - 1 : nu - 1;
  const double m = ViewMu(k, r);
  const double left = k > lo ? ViewMu(k - 1, r) : m;
  const double right = k < hi ? ViewMu(k + 1, r) : m;
  return 0.5 * (right - left);
}

void Nodes::ViewIndex(double mu, double r, size_t* k0, size_t* k1, double* t) const {
  const double mh = HorizonMu(r);
  const double th = std::acos(mh), theta = std::acos(std::clamp(mu, -1.0, 1.0));
  const double ip = 1.0 / view_power;
  double f;
  size_t base, n;
  if (mu >= mh) {
    const double s = std::pow(std::clamp(1.0 - theta / th, 0.0, 1.0), ip);
    f = s * (nup - 1);
    base = static_cast<size_t>(ndn);
    n = static_cast<size_t>(nup);
  } else {
    const double s = 1.0 - std::pow(std::clamp((theta - th) / (kPi - th), 0.0, 1.0), ip);
    f = s * (ndn - 1);
    base = 0;
    n = static_cast<size_t>(ndn);
  }
  f = std::clamp(f, 0.0, static_cast<double>(n - 1));
  const size_t i = std::min(static_cast<size_t>(f), n - 2);
  *k0 = base + i;
  *k1 = base + i + 1;
  *t = f - static_cast<double>(i);
}

// The sky is even in the azimuth about the sun's vertical plane, so near phi = 0 and pi it goes
// as a + b phi^2 (a + b (pi - phi)^2): with `even`, the first and last intervals, and beyond the
// outer nodes (within pi / 2n of those planes), blend linearly in phi^2 ((pi - phi)^2), not in
// phi. Clamping there takes the value of the node 11.25 deg from the sun for the sun's plane
// itself, under the forward lobe (hazed, sun 70 deg: -6 % at the horizon towards the sun; the
// output's blend is what matters: inside the table build the sources are smooth in azimuth and
// the blend changes them by <= 0.01 %).
double Nodes::AzimuthBlend(double phi, bool even, size_t* q0) const {
  double fq = phi / kPi * nphi - 0.5;
  fq = std::clamp(fq, 0.0, static_cast<double>(nphi - 1));
  *q0 = std::min(static_cast<size_t>(fq), static_cast<size_t>(nphi - 2));
  double tq = fq - static_cast<double>(*q0);
  if (even) {
    auto sq = [](double x) { return x * x; };
    const double p0 = (*q0 + 0.5) * kPi / nphi, p1 = (*q0 + 1.5) * kPi / nphi;
    if (*q0 == 0) tq = (sq(phi) - sq(p0)) / (sq(p1) - sq(p0));
    else if (*q0 + 2 == static_cast<size_t>(nphi)) tq = 1.0 - (sq(kPi - phi) - sq(kPi - p1)) / (sq(kPi - p0) - sq(kPi - p1));
  }
  return tq;
}

void Nodes::CellGeometry(size_t ri, size_t si, size_t k, size_t q, double* mu, double* nu_s) const {
  const double r = radius[ri];
  *mu = ViewMu(k, r);
  const double phi = (q + 0.5) * kPi / nphi;
  const double ts = sun_theta_rad[si];
  *nu_s = std::sqrt(std::max(0.0, 1.0 - *mu * *mu)) * std::cos(phi) * std::sin(ts) + *mu * std::cos(ts);
}

RadialView Nodes::RadialViewAt(double r, double mu) const {
  RadialView v;
  const Lerp lr = Locate(radius, r);
  v.ri = lr.i;
  v.wr[0] = 1.0 - lr.t;
  v.wr[1] = lr.t;
  for (int dr = 0; dr < 2; ++dr) {
    if (v.wr[dr] == 0.0) continue;
    ViewIndex(mu, radius[lr.i + static_cast<size_t>(dr)], &v.k0[dr], &v.k1[dr], &v.tk[dr]);
  }
  return v;
}

SunAzimuth Nodes::SunAzimuthAt(double theta_s, double cos_phi, bool even) const {
  SunAzimuth sa;
  if (theta_s > sun_theta_rad.back()) {
    sa.si = kNoSun;
    return sa;
  }
  const Lerp ls = Locate(sun_loc, theta_s);
  size_t q0;
  const double tq = AzimuthBlend(std::acos(std::clamp(cos_phi, -1.0, 1.0)), even, &q0);
  sa.si = static_cast<uint16_t>(ls.i);
  sa.q0 = static_cast<uint16_t>(q0);
  sa.ts = static_cast<float>(ls.t);
  sa.tq = static_cast<float>(tq);
  return sa;
}

void Nodes::Interpolate(const Table& tab, const RadialView& rv, const SunAzimuth& sa, double weight, float* acc) const {
  if (sa.si == kNoSun) return;  // beyond the last sun node: no light
  const Lerp ls{sa.si, sa.ts};
  const size_t q0 = sa.q0;
  const double tq = sa.tq;
  for (int dr = 0; dr < 2; ++dr) {
    const size_t ri = rv.ri + static_cast<size_t>(dr);
    const double wr = rv.wr[dr];
    if (wr == 0.0) continue;
    const size_t k0 = rv.k0[dr], k1 = rv.k1[dr];
    const double tk = rv.tk[dr];
    for (int ds = 0; ds < 2; ++ds) {
      const size_t si = ls.i + static_cast<size_t>(ds);
      const double ws = wr * (ds ? ls.t : 1.0 - ls.t);
      if (ws == 0.0) continue;
      for (int dk = 0; dk < 2; ++dk) {
        const double wk = ws * (dk ? tk : 1.0 - tk);
        if (wk == 0.0) continue;
        const size_t k = dk ? k1 : k0;
        for (int dq = 0; dq < 2; ++dq) {
          const float wq = static_cast<float>(weight * wk * (dq ? tq : 1.0 - tq));
          if (wq == 0.0f) continue;
          const float* v = &tab[Cell(ri, si, k, q0 + static_cast<size_t>(dq)) * nw];
          for (size_t w = 0; w < nw; ++w) acc[w] += wq * v[w];
        }
      }
    }
  }
}

}  // namespace skybake::orders
