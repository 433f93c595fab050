// The scattering step of `orders`: J_n = sum_c sigma_s*_c P*_c applied to L_{n-1} at every node,
// per radius a kernel over the direction nodes, stored per unit sigma_s* (J / sigma_s*: the
// phase-weighted mean radiance), multiplied back by sigma_s* where it is used. Interpolating J
// itself between radius nodes smears a thin dense layer's source over the whole interval (a 1 km
// water cloud of optical depth 8 is then amplified each order by 1.29).
// Two forms: the (nd x nd) matrix (this file's kernel.cpp, the plain form) and the azimuthal
// cosine modes (modal_kernel.cpp, the fast form); docs/sky-methods.md "Scattering kernel".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "transport/orders/grid.h"
#include "transport/orders/medium.h"
#include "transport/orders/nodes.h"

namespace skybake::orders {

// The view nodes at a radius: cosine, sine and trapezoid width in mu (both kernel builders).
struct ViewNodes {
  std::vector<double> mu, sn, width;
};

struct KernelContext {
  const Medium* md = nullptr;
  const Nodes* nodes = nullptr;
  const OrdersSettings* s = nullptr;
  size_t nd = 0;                  // directions per (radius, sun): nu nphi
  std::vector<double> ssc_total;  // sigma_s* at each radius node [ri * nw + w] (m^-1)

  // The mixture phase x scattering coefficient sum_c sigma_s*_c P*_c on the cos grid at radius node ri.
  std::vector<float> Mixture(size_t ri) const;
  // scale x the mixture at cosine mu, accumulated into out[w].
  void MixtureAt(const std::vector<float>& mix, double mu, float scale, float* out) const;
  ViewNodes ViewNodesAt(double r) const;
  // The basis kernel's quadrature (both forms, matrix and modal): for every view sub-interval
  // (kernel_sub per view interval, midpoint rule in the view-node index f) and every output view
  // node k, the mixture phase at the 2 na azimuth offsets (m + 1/2) u, u = pi / (2 sub nphi),
  // into pm[m * nw + w]; then fn(k, kn, wk, dmu, pm) with kn the sub-interval's two view nodes, wk
  // their hat weights at its midpoint and dmu its width in mu. The node azimuths are
  // (q + 1/2) pi / nphi = (2 sub q + sub + 1/2) u, so every phi_q -+ phi_a is a half-integer
  // multiple of u and the phase is evaluated once per multiple.
  template <class Fn>
  void ForEachViewSubsample(double r, const std::vector<float>& mix, const std::vector<double>& vmu, const std::vector<double>& vsn,
                            const Fn& fn) const;
};

KernelContext MakeKernelContext(const Medium& md, const Nodes& nodes, const OrdersSettings& s);

// The kernels, built once for every order: the modal ones always; the matrices when all radii fit
// in 768 MiB (medium: 17 x 192^2 x nw floats, 60 MiB at 24 wavelengths), else rebuilt per order
// and radius.
struct ScatterKernels {
  bool modal = true;
  bool has_ends = false;       // the modal form's end columns (the basis kernel with the even blend)
  size_t nm = 0;               // modes: nphi
  std::vector<float> cos_mq;   // cos(m theta_q) [m * nphi + q]
  size_t modal_floats = 0;     // G[((m * nu + k) * nu + k2) * nw + w] per radius
  size_t end_floats = 0;       // D[((k * nphi + q) * nu + k2) * nw + w] per radius (both ends: modal_kernel.cpp)
  // G and D per unit sigma_s* (J / sigma_s* comes out of the products): floats, or binary16
  // (OrdersSettings::kernel_half). Per unit sigma_s* the values are 1e-5..1, normal halves; in
  // m^-1 they would fall among the half's subnormals.
  bool half = false;
  Table modal_kernels, end_kernels;
  std::vector<uint16_t> modal_half, end_half;
  size_t kernel_floats = 0;    // the matrix: nd x nd x nw per radius
  std::vector<float> kernels;  // empty: rebuilt per order
};

ScatterKernels BuildScatterKernels(const KernelContext& kc);
// What BuildScatterKernels holds per wavelength (bytes, all radius nodes): the modal G and D, or
// the matrices.
size_t KernelBytesPerWavelength(const Nodes& nodes, const OrdersSettings& s);
// Jout = the scattering of Lin (cells x nw each), per unit sigma_s*.
void Scatter(const KernelContext& kc, const ScatterKernels& sk, const Table& Lin, Table* Jout);

// The two forms (kernel.cpp, modal_kernel.cpp).
void BuildMatrixKernel(const KernelContext& kc, size_t ri, float* kernel);
void ScatterMatrix(const KernelContext& kc, const ScatterKernels& sk, const Table& Lin, Table* Jout);
void BuildModalKernels(const KernelContext& kc, ScatterKernels* sk);
void ScatterModal(const KernelContext& kc, const ScatterKernels& sk, const Table& Lin, Table* Jout);

template <class Fn>
void KernelContext::ForEachViewSubsample(double r, const std::vector<float>& mix, const std::vector<double>& vmu,
                                         const std::vector<double>& vsn, const Fn& fn) const {
  const size_t nw = md->nw, nu = nodes->nu, nphi = static_cast<size_t>(s->nphi);
  const int sub = s->kernel_sub;
  const size_t na = nphi * 2 * static_cast<size_t>(sub);
  const double u = kPi / static_cast<double>(na);
  std::vector<double> cosm(2 * na);
  for (size_t m = 0; m < 2 * na; ++m) cosm[m] = std::cos((m + 0.5) * u);
  std::vector<float> pm(2 * na * nw);
  for (int set = 0; set < 2; ++set) {
    const bool down = set == 0;
    const int n = down ? s->ndn : s->nup;
    const size_t base = down ? 0 : static_cast<size_t>(s->ndn);
    for (int kk = 0; kk + 1 < n; ++kk) {
      for (int b = 0; b < sub; ++b) {
        const double f0 = kk + static_cast<double>(b) / sub, f1 = kk + static_cast<double>(b + 1) / sub;
        const double fm = 0.5 * (f0 + f1), tk = fm - kk;
        const double m2 = nodes->ViewMuAt(down, fm, r), s2 = std::sqrt(std::max(0.0, 1.0 - m2 * m2));
        const double dmu = std::abs(nodes->ViewMuAt(down, f1, r) - nodes->ViewMuAt(down, f0, r));
        const size_t kn[2] = {base + static_cast<size_t>(kk), base + static_cast<size_t>(kk) + 1};
        const double wk[2] = {1.0 - tk, tk};
        for (size_t k = 0; k < nu; ++k) {
          const double cc = vmu[k] * m2, ss = vsn[k] * s2;
          std::fill(pm.begin(), pm.end(), 0.0f);
          for (size_t m = 0; m < 2 * na; ++m) MixtureAt(mix, cc + ss * cosm[m], 1.0f, &pm[m * nw]);
          fn(k, kn, wk, dmu, pm);
        }
      }
    }
  }
}

}  // namespace skybake::orders
