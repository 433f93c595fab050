#include "transport/orders/acceleration.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace skybake::orders {

namespace {

// The first moment g* = <mu> of component c's truncated phase at every wavelength (trapezoid on
// the phase grid; the cone's flat top is part of P*).
std::vector<double> TruncatedAsymmetry(const Medium& md, size_t c) {
  const int ng = Medium::kPhaseGrid;
  std::vector<double> num(md.nw, 0.0), den(md.nw, 0.0);
  for (int g = 0; g < ng; ++g) {
    const double mu = -1.0 + 2.0 * g / (ng - 1);
    const double wt = g == 0 || g == ng - 1 ? 0.5 : 1.0;
    for (size_t w = 0; w < md.nw; ++w) {
      const double p = md.phase_star[(c * ng + g) * md.nw + w];
      num[w] += wt * p * mu;
      den[w] += wt * p;
    }
  }
  for (size_t w = 0; w < md.nw; ++w) num[w] = den[w] > 0.0 ? num[w] / den[w] : 0.0;
  return num;
}

// Solves the tridiagonal system (lower l, diagonal d, upper u, right side b) in place into b
// (Thomas algorithm; the diffusion matrix is diagonally dominant).
void SolveTridiagonal(std::vector<double>& l, std::vector<double>& d, std::vector<double>& u, std::vector<double>& b) {
  const size_t n = d.size();
  for (size_t i = 1; i < n; ++i) {
    const double m = l[i] / d[i - 1];
    d[i] -= m * u[i - 1];
    b[i] -= m * b[i - 1];
  }
  b[n - 1] /= d[n - 1];
  for (size_t i = n - 1; i-- > 0;) b[i] = (b[i] - u[i] * b[i + 1]) / d[i];
}

}  // namespace

DiffusionAcceleration MakeDiffusionAcceleration(const Medium& md, const Nodes& nodes, const KernelContext& kc) {
  DiffusionAcceleration a;
  const size_t nw = md.nw, nr = nodes.radius.size(), nu = nodes.nu, nphi = static_cast<size_t>(nodes.nphi);
  a.nr = nr;
  a.ns = nodes.ns;
  a.nu = nu;
  a.nphi = nphi;
  a.nw = nw;
  // Solid angles: the view node's trapezoid width in mu times 2 pi / nphi (each azimuth cell on
  // [0, pi] stands for its mirror image too), normalised to 4 pi per radius.
  a.weight.assign(nr * nu, 0.0);
  for (size_t ri = 0; ri < nr; ++ri) {
    double sum = 0.0;
    for (size_t k = 0; k < nu; ++k) {
      a.weight[ri * nu + k] = nodes.ViewWidth(k, nodes.radius[ri]);
      sum += a.weight[ri * nu + k] * static_cast<double>(nphi);
    }
    for (size_t k = 0; k < nu; ++k) a.weight[ri * nu + k] *= 4.0 * kPi / sum;
  }
  // sigma_s*, sigma_a* and sigma_tr* = sigma_t* - sum_c sigma_s*_c g*_c at the radius nodes.
  std::vector<std::vector<double>> g(md.nc);
  for (size_t c = 0; c < md.nc; ++c) g[c] = TruncatedAsymmetry(md, c);
  std::vector<double> tr(nr * nw);
  a.absorption.assign(nr * nw, 0.0);
  a.scattering.assign(nr * nw, 0.0);
  std::vector<float> st(nw), ss(nw);
  const double R = nodes.bottom_radius_m;
  for (size_t ri = 0; ri < nr; ++ri) {
    const AtmosphereModel::Cell cell = md.m->Locate(nodes.radius[ri] - R);
    md.SigmaT(cell, true, st.data());
    for (size_t w = 0; w < nw; ++w) tr[ri * nw + w] = st[w];
    for (size_t c = 0; c < md.nc; ++c) {
      md.SigmaS(c, cell, true, ss.data());
      for (size_t w = 0; w < nw; ++w) tr[ri * nw + w] -= ss[w] * g[c][w];
    }
    for (size_t w = 0; w < nw; ++w) {
      a.scattering[ri * nw + w] = kc.ssc_total[ri * nw + w];
      a.absorption[ri * nw + w] = std::max(0.0, st[w] - kc.ssc_total[ri * nw + w]);
    }
  }
  // D / dz over each interval: 1 / (3 tau_tr) with tau_tr the trapezoid of sigma_tr* (capped at
  // 1e6: a vacuum's infinite coupling, which only flattens the flux there).
  a.coupling.assign((nr - 1) * nw, 0.0);
  a.volume.assign(nr, 0.0);
  for (size_t i = 0; i + 1 < nr; ++i) {
    const double dz = nodes.radius[i + 1] - nodes.radius[i];
    a.volume[i] += 0.5 * dz;
    a.volume[i + 1] += 0.5 * dz;
    for (size_t w = 0; w < nw; ++w) {
      const double tau = 0.5 * (tr[i * nw + w] + tr[(i + 1) * nw + w]) * dz;
      a.coupling[i * nw + w] = tau > 1.0 / 3e6 ? 1.0 / (3.0 * tau) : 1e6;
    }
  }
  a.ground_loss.resize(nw);
  for (size_t w = 0; w < nw; ++w) a.ground_loss[w] = (1.0 - md.albedo[w]) / (2.0 * (1.0 + md.albedo[w]));
  a.share.assign(a.ns, 0.0);
  const double end = std::min(nodes.sun_theta_rad.back() / kDeg, kTaperEndDeg);
  for (size_t si = 0; si < a.ns; ++si) {  // kShare, tapered (acceleration.h)
    a.share[si] = kShare * std::clamp((end - nodes.sun_theta_rad[si] / kDeg) / kTaperDeg, 0.0, 1.0);
  }
  a.iso.assign(nr * a.ns * nw, 0.0f);
  return a;
}

double ScaledColumnDepth(const Medium& md, const Nodes& nodes) {
  const double R = nodes.bottom_radius_m;
  double tau = 0.0;
  for (size_t i = 0; i + 1 < nodes.radius.size(); ++i) {
    const double s0 = md.SigmaTAt(nodes.radius[i] - R, true, md.wref), s1 = md.SigmaTAt(nodes.radius[i + 1] - R, true, md.wref);
    tau += 0.5 * (s0 + s1) * (nodes.radius[i + 1] - nodes.radius[i]);
  }
  return tau;
}

void Accelerate(DiffusionAcceleration* a, Table* L) {
  const size_t nr = a->nr, ns = a->ns, nu = a->nu, nphi = a->nphi, nw = a->nw, nd = nu * nphi;
  // L -= the previous correction; the scalar flux of what is left per (radius, sun, wavelength).
  // A sun node without a share keeps a zero correction: its cells are left as they are.
  std::vector<double> flux(nr * ns * nw, 0.0);
  tbb::parallel_for(size_t{0}, nr * ns, [&](size_t b) {
    if (!(a->share[b % ns] > 0.0)) return;
    const size_t ri = b / ns;
    const float* ci = &a->iso[b * nw];
    double* fx = &flux[b * nw];
    for (size_t k = 0; k < nu; ++k) {
      const double wt = a->weight[ri * nu + k];
      for (size_t q = 0; q < nphi; ++q) {
        float* v = &(*L)[(b * nd + k * nphi + q) * nw];
        for (size_t w = 0; w < nw; ++w) {
          v[w] -= ci[w];
          fx[w] += wt * v[w];
        }
      }
    }
  });
  // Per sun node and wavelength the diffusion equation over the radius nodes (finite volumes:
  // node i holds volume[i] of the column; Marshak conditions: the top loses phi / 2, the ground
  // (1 - A) / (2 (1 + A)) phi).
  tbb::parallel_for(size_t{0}, ns, [&](size_t si) {
    if (!(a->share[si] > 0.0)) return;
    std::vector<double> l(nr), d(nr), u(nr), rhs(nr);
    for (size_t w = 0; w < nw; ++w) {
      for (size_t i = 0; i < nr; ++i) {
        const double cl = i > 0 ? a->coupling[(i - 1) * nw + w] : 0.0;
        const double cu = i + 1 < nr ? a->coupling[i * nw + w] : 0.0;
        l[i] = -cl;
        u[i] = -cu;
        d[i] = cl + cu + a->absorption[i * nw + w] * a->volume[i];
        rhs[i] = a->scattering[i * nw + w] * flux[(i * ns + si) * nw + w] * a->volume[i];
      }
      d[0] += a->ground_loss[w];
      d[nr - 1] += 0.5;
      SolveTridiagonal(l, d, u, rhs);
      // The correction: isotropic, phi / (4 pi), its share applied.
      for (size_t i = 0; i < nr; ++i) a->iso[(i * ns + si) * nw + w] = static_cast<float>(a->share[si] * rhs[i] / (4.0 * kPi));
    }
  });
  tbb::parallel_for(size_t{0}, nr * ns, [&](size_t b) {
    if (!(a->share[b % ns] > 0.0)) return;
    const float* ci = &a->iso[b * nw];
    for (size_t c = 0; c < nd; ++c) {
      float* v = &(*L)[(b * nd + c) * nw];
      for (size_t w = 0; w < nw; ++w) v[w] += ci[w];
    }
  });
}

}  // namespace skybake::orders
