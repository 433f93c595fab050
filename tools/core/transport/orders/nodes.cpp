#include "transport/orders/nodes.h"

#include <algorithm>
#include <cmath>

#include "atmosphere/model.h"
#include "atmosphere/ray_sphere.h"

namespace skybake::orders {

// Radius nodes uniform in s(h) = (tau(0,h)/tau(0,H) + (h/H)^0.4) / 2, tau the vertical optical
// depth at the grid's middle wavelength: the altitude part alone is h_i = H (i/(n-1))^2.5 (0, 0.12,
// 0.65, 1.8, 3.7, 6.4, 10 ... 100 km for n = 16), the optical-depth part puts half the nodes where
// the extinction is, so that a 2 km thick water cloud at 3.5-5.5 km (cloudy4) has nodes inside it
// (interpolated from outside the cloud, its sources make the sky under it 3-5x too dark).
//
// The nodes are 1/(n-1) apart in s, and s grows by half the column's fraction of optical depth, so
// an interval holds at most 2 tau_total/(n-1) of it. Inside a cloud the sources J/sigma_s change by
// a large factor over one optical depth (the diffuse light builds up below the cloud top and fades
// towards its base), and the linear blend between nodes is then what limits the sky under it:
// cloudy3 (tau 4.2) at `high` with 16 nodes (0.56 per interval) is +2 ... +6.6 % against its 1 %
// path reference, with 32 nodes (0.28) within 2 % (docs/sky-methods.md "Radius nodes under a cloud").
int RadiusNodeCount(const OrdersSettings& s, double tau_total) {
  if (s.radius_dtau <= 0.0) return s.nr;
  const double need = 1.0 + std::ceil(2.0 * tau_total / s.radius_dtau);
  return std::max(s.nr, static_cast<int>(std::min(need, static_cast<double>(s.radius_max))));
}

Nodes BuildNodes(const AtmosphereModel& m, const OrdersSettings& s, double observer_altitude_m) {
  Nodes n;
  n.bottom_radius_m = m.bottom_radius_m;
  n.nup = s.nup, n.ndn = s.ndn, n.nphi = s.nphi, n.view_power = s.view_power;
  n.nw = m.wavelengths();
  const double R = m.bottom_radius_m, H = m.top_radius_m - R;
  const size_t wref = m.wavelengths() / 2;
  const double tau_total = std::max(m.VerticalOpticalDepth(0.0, H, wref), 1e-12);
  auto s_of = [&](double h) { return 0.5 * (m.VerticalOpticalDepth(0.0, h, wref) / tau_total + std::pow(h / H, 0.4)); };
  for (double h : AltitudesUniformIn(s_of, RadiusNodeCount(s, tau_total), H)) n.radius.push_back(R + h);
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
  const Lerp ls = Locate(sun_theta_rad, theta_s);
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
