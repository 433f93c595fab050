// The kernel in azimuthal cosine modes. The phase depends on the azimuth only through the
// difference of the two azimuths, and the table is even about the sun's plane: on the circle of
// the 2 nphi azimuths theta_j = (j + 1/2) pi / nphi (the nodes and their mirror images) the
// kernel is a circulant c(q - j), and with L even its product is diagonal in the cosine modes
// cos(m theta), m < nphi (m = nphi vanishes at every node; m and 2 nphi - m fold onto each
// other): S_m(k2) = sum_q L(k2, q) cos(m theta_q), T_m(k) = sum_k2 G_m(k, k2) S_m(k2),
// J(k, q) = sum_m T_m(k) cos(m theta_q), with G_m = (m ? 2 : 1) / nphi sum_d c(d) cos(m d pi /
// nphi). Per radius and sun node nu^2 nphi + 2 nu nphi^2 products instead of (nu nphi)^2: 10x
// fewer for high (36 view x 24 azimuth nodes), whose matrix would not fit in memory. The basis
// kernel's azimuth hats are translates of one another except in the two end intervals, where the
// even blend (Nodes::AzimuthBlend) departs from the linear one: that difference is kept as
// explicit columns per view node, D(k, q, k2) applied to L(k2, 0) - L(k2, 1) at the end by phi = 0
// and, mirrored, D(k, nphi - 1 - q, k2) applied to L(k2, nphi - 1) - L(k2, nphi - 2) at the end by
// phi = pi. The mirror is exact: with psi = pi - phi the even and the linear weights of the far
// interval are those of the near one at psi, the node azimuths map onto each other (theta_q ->
// pi - theta_q), and the phase depends only on cos(theta_q -+ phi), which the map keeps; so one
// end's columns serve both (half of D: 9 MB per radius for high instead of 18 MB). The same
// values as the matrix to float rounding (test MethodOrders.ModalKernelIsTheMatrixKernel).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <Imath/half.h>

#include "transport/orders/kernel.h"
#include "transport/orders/simd.h"

namespace skybake::orders {

namespace {

// The circulant's coefficients c[((k * nu + k2) * N + d) * nw + w] of the phase sampled at the
// nodes: c(d) = P(v_k . v_k2 at azimuth difference d pi / nphi) dmu_k2 pi / nphi.
void CoefficientsAtNodes(const KernelContext& kc, const ViewNodes& vn, const std::vector<float>& mix, std::vector<double>* c) {
  const OrdersSettings& s = *kc.s;
  const size_t nw = kc.md->nw, nu = kc.nodes->nu, N = 2 * static_cast<size_t>(s.nphi);
  std::vector<float> cd(nw);
  for (size_t k = 0; k < nu; ++k) {
    for (size_t k2 = 0; k2 < nu; ++k2) {
      const double wgt = vn.width[k2] * kPi / s.nphi;
      for (size_t d = 0; d < N; ++d) {
        std::fill(cd.begin(), cd.end(), 0.0f);
        kc.MixtureAt(mix, vn.mu[k] * vn.mu[k2] + vn.sn[k] * vn.sn[k2] * std::cos(d * kPi / s.nphi), 1.0f, cd.data());
        double* o = &(*c)[((k * nu + k2) * N + d) * nw];
        for (size_t w = 0; w < nw; ++w) o[w] = wgt * cd[w];
      }
    }
  }
}

// The same for the basis kernel (ForEachViewSubsample's quadrature, as the matrix's): azimuth
// sub-samples phi_a = (a + 1/2) u, u = pi / (2 sub nphi); the linear hat of node 0 is
// 1 - |e| / (2 sub) at phi_a - theta_0 = e u, so c(d) = u sum_e hat(e) P(cos((2 sub d - e) u)).
// With has_ends, dc gets the end columns of the end by phi = 0 (before their scaling).
void CoefficientsOfBasis(const KernelContext& kc, double r, const ViewNodes& vn, const std::vector<float>& mix, bool has_ends,
                         std::vector<double>* c, std::vector<double>* dc) {
  const OrdersSettings& s = *kc.s;
  const size_t nw = kc.md->nw, nu = kc.nodes->nu, nphi = static_cast<size_t>(s.nphi), N = 2 * nphi;
  const int sub = s.kernel_sub;
  const size_t per = 2 * static_cast<size_t>(sub), na = nphi * per;
  const double u = kPi / static_cast<double>(na);
  // The end intervals' departure of the even blend from the linear one at each sub-sample.
  struct EndSample {
    size_t a;
    double dw;  // (linear - even) weight of the interval's lower node
  };
  std::vector<EndSample> ends;
  if (has_ends) {
    for (size_t a = 0; a < na; ++a) {
      size_t q0, q1;
      const double te = kc.nodes->AzimuthBlend((a + 0.5) * u, true, &q0), tl = kc.nodes->AzimuthBlend((a + 0.5) * u, false, &q1);
      if (te != tl && q0 == 0) ends.push_back({a, tl - te});
    }
  }
  std::vector<double> hat(2 * per);
  for (size_t i = 0; i < 2 * per; ++i) hat[i] = 1.0 - std::abs(static_cast<double>(i) - static_cast<double>(per) + 0.5) / static_cast<double>(per);
  std::vector<float> cd(nw);
  kc.ForEachViewSubsample(r, mix, vn.mu, vn.sn, [&](size_t k, const size_t* kn, const double* wk_hat, double dmu, const std::vector<float>& pm) {
    const double wk[2] = {wk_hat[0] * dmu * u, wk_hat[1] * dmu * u};
    for (size_t d = 0; d < N; ++d) {
      std::fill(cd.begin(), cd.end(), 0.0f);
      for (size_t i = 0; i < 2 * per; ++i) {
        // phi_a - theta_0 = e u with e = i - per + 1/2; the difference theta_d - phi_a = (2 sub d - e) u.
        const double nn = std::abs(static_cast<double>(per * d) - (static_cast<double>(i) - static_cast<double>(per) + 0.5));
        const float* pv = &pm[static_cast<size_t>(nn - 0.5) * nw];
        const float h = static_cast<float>(hat[i]);
        for (size_t w = 0; w < nw; ++w) cd[w] += h * pv[w];
      }
      for (int x = 0; x < 2; ++x) {
        double* o = &(*c)[((k * nu + kn[x]) * N + d) * nw];
        for (size_t w = 0; w < nw; ++w) o[w] += wk[x] * cd[w];
      }
    }
    for (const EndSample& es : ends) {
      for (size_t q = 0; q < nphi; ++q) {
        const long dlt = static_cast<long>(q * per + static_cast<size_t>(sub)) - static_cast<long>(es.a);
        const size_t md = static_cast<size_t>(dlt >= 1 ? dlt - 1 : -dlt), ms = q * per + static_cast<size_t>(sub) + es.a;
        for (int x = 0; x < 2; ++x) {
          double* o = &(*dc)[((k * nphi + q) * nu + kn[x]) * nw];
          const double wgt = wk[x] * es.dw;
          for (size_t w = 0; w < nw; ++w) o[w] += wgt * (pm[md * nw + w] + pm[ms * nw + w]);
        }
      }
    }
  });
}

// G (and D, if not null) at radius node ri from the coefficients, per unit sigma_s*, with every
// row scaled to sum to 1 (energy conservation, as the matrix's rows sum to sigma_s*: a row's sum is
// sum_k2 sum_d c(d), the same for every azimuth; the end columns add nothing). Without scattering
// (sigma_s* = 0) the row is 0.
void ModesFromCoefficients(const KernelContext& kc, size_t ri, const std::vector<double>& c, const std::vector<double>& dc, float* G,
                           float* D) {
  const OrdersSettings& s = *kc.s;
  const size_t nw = kc.md->nw, nu = kc.nodes->nu, nphi = static_cast<size_t>(s.nphi), N = 2 * nphi, nm = nphi;
  std::vector<double> cosd(nm * N);
  for (size_t m = 0; m < nm; ++m) {
    for (size_t d = 0; d < N; ++d) cosd[m * N + d] = std::cos(static_cast<double>(m * d) * kPi / s.nphi);
  }
  std::vector<double> scale(nw), v(nw);
  for (size_t k = 0; k < nu; ++k) {
    std::fill(scale.begin(), scale.end(), 0.0);
    for (size_t k2 = 0; k2 < nu; ++k2) {
      for (size_t d = 0; d < N; ++d) {
        const double* cv = &c[((k * nu + k2) * N + d) * nw];
        for (size_t w = 0; w < nw; ++w) scale[w] += cv[w];
      }
    }
    for (size_t w = 0; w < nw; ++w) {
      const double st = kc.ssc_total[ri * nw + w];
      scale[w] = !(st > 0.0) ? 0.0 : s.normalise && scale[w] > 0.0 ? 1.0 / scale[w] : 1.0 / st;
    }
    for (size_t m = 0; m < nm; ++m) {
      const double f = (m == 0 ? 1.0 : 2.0) / s.nphi;
      for (size_t k2 = 0; k2 < nu; ++k2) {
        float* g = &G[((m * nu + k) * nu + k2) * nw];
        // v[w] = sum_d c(d) cos(m d pi / nphi), d ascending, every wavelength at once.
        std::fill(v.begin(), v.end(), 0.0);
        for (size_t d = 0; d < N; ++d) {
          const double* cv = &c[((k * nu + k2) * N + d) * nw];
          const double cm = cosd[m * N + d];
          for (size_t w = 0; w < nw; ++w) v[w] += cv[w] * cm;
        }
        for (size_t w = 0; w < nw; ++w) g[w] = static_cast<float>(f * scale[w] * v[w]);
      }
    }
    if (D == nullptr) continue;
    for (size_t q = 0; q < nphi; ++q) {
      for (size_t k2 = 0; k2 < nu; ++k2) {
        const size_t o = ((k * nphi + q) * nu + k2) * nw;
        for (size_t w = 0; w < nw; ++w) D[o + w] = static_cast<float>(scale[w] * dc[o + w]);
      }
    }
  }
}

// A thread's double coefficients of one radius (54 MB for high), zeroed anew for each radius in
// memory the thread keeps, not allocated per radius (fresh pages of that size cost a page fault
// each and are zeroed by the kernel before the vector zeroes them again); and the radius's G and
// D as floats before they are stored.
struct CoefficientScratch {
  std::vector<double> c, dc;
  std::vector<float> g, d;
};

void BuildModalKernel(const KernelContext& kc, ScatterKernels* sk, size_t ri, CoefficientScratch* x) {
  const size_t nw = kc.md->nw, nu = kc.nodes->nu, N = 2 * static_cast<size_t>(kc.s->nphi);
  const double r = kc.nodes->radius[ri];
  const std::vector<float> mix = kc.Mixture(ri);
  const ViewNodes vn = kc.ViewNodesAt(r);
  std::vector<double>& c = x->c;  // c[((k * nu + k2) * N + d) * nw + w]
  std::vector<double>& dc = x->dc;
  c.assign(nu * nu * N * nw, 0.0);
  dc.assign(sk->end_floats, 0.0);
  x->g.resize(sk->modal_floats);
  x->d.resize(sk->end_floats);
  if (kc.s->kernel_sub == 0) CoefficientsAtNodes(kc, vn, mix, &c);
  else CoefficientsOfBasis(kc, r, vn, mix, sk->has_ends, &c, &dc);
  ModesFromCoefficients(kc, ri, c, dc, x->g.data(), sk->has_ends ? x->d.data() : nullptr);
  const size_t g0 = ri * sk->modal_floats, d0 = ri * sk->end_floats;
  if (sk->half) {
    for (size_t i = 0; i < x->g.size(); ++i) sk->modal_half[g0 + i] = imath_float_to_half(x->g[i]);
    for (size_t i = 0; i < x->d.size(); ++i) sk->end_half[d0 + i] = imath_float_to_half(x->d[i]);
  } else {
    std::copy(x->g.begin(), x->g.end(), sk->modal_kernels.begin() + static_cast<std::ptrdiff_t>(g0));
    std::copy(x->d.begin(), x->d.end(), sk->end_kernels.begin() + static_cast<std::ptrdiff_t>(d0));
  }
}

}  // namespace

void BuildModalKernels(const KernelContext& kc, ScatterKernels* sk) {
  const OrdersSettings& s = *kc.s;
  const size_t nw = kc.md->nw, nu = kc.nodes->nu, nphi = static_cast<size_t>(s.nphi), nr = kc.nodes->radius.size();
  sk->nm = nphi;
  sk->cos_mq.resize(sk->nm * nphi);
  for (size_t m = 0; m < sk->nm; ++m) {
    for (size_t q = 0; q < nphi; ++q) sk->cos_mq[m * nphi + q] = static_cast<float>(std::cos(static_cast<double>(m) * (q + 0.5) * kPi / s.nphi));
  }
  sk->has_ends = s.kernel_sub > 0 && s.azimuth_even;
  sk->modal_floats = sk->nm * nu * nu * nw;
  sk->end_floats = sk->has_ends ? nu * nphi * nu * nw : 0;
  sk->half = s.kernel_half;
  if (sk->half) {
    sk->modal_half.resize(nr * sk->modal_floats);
    sk->end_half.resize(nr * sk->end_floats);
  } else {
    ZeroTable(&sk->modal_kernels, nr * sk->modal_floats);
    ZeroTable(&sk->end_kernels, nr * sk->end_floats);
  }
  {
    tbb::enumerable_thread_specific<CoefficientScratch> scratch;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr, 1), [&](const tbb::blocked_range<size_t>& rg) {
      CoefficientScratch& x = scratch.local();
      for (size_t ri = rg.begin(); ri != rg.end(); ++ri) {
        BuildModalKernel(kc, sk, ri, &x);
      }
    });
  }  // the scratch is freed before the solve's tables are allocated (the peak, docs/sky-methods.md "Peak memory")
}

// The three products run 8 wavelengths wide (simd.h), each sum in the order of the plain loops
// (analysis: q ascending; modes: k2 ascending; synthesis: m ascending, then the end columns e, k2
// ascending). Tasks (radius, block of up to 16 sun nodes): G (nm nu^2 nw values per radius, 4.5 MB
// as binary16 for high at 48 wavelengths) and D (as much, read once per end) do not fit in cache
// and are read once per task; within a task each G or D slice (nu nw values) serves the 4
// sub-blocks of 4 sun nodes while in L1 (with tasks of 4 sun nodes high's scatter is bound by
// reading G once and D twice, 11 times per order). K: the kernels' storage, float or binary16
// (uint16_t).
template <class K>
void ScatterModalAs(const KernelContext& kc, const ScatterKernels& sk, const K* Gall, const K* Dall, const Table& Lin, Table* Jout) {
  const size_t nw = kc.md->nw, nu = kc.nodes->nu, ns = kc.nodes->ns, nphi = static_cast<size_t>(kc.s->nphi);
  const size_t nr = kc.nodes->radius.size(), nd = kc.nd, nm = sk.nm;
  const bool has_ends = sk.has_ends;
  constexpr size_t kSub = 4, kSunBlock = 16;
  const size_t nsb = (ns + kSunBlock - 1) / kSunBlock;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nsb, 1), [&](const tbb::blocked_range<size_t>& rg) {
    // S[b][m][k2][w], T[b][k][m][w], dL[b][e][k2][w]; a short last sub-block computes its
    // unused b from what the buffers hold (zeros or an earlier block's finite values) and
    // stores nothing of them.
    std::vector<float> S(kSunBlock * nm * nu * nw, 0.0f), T(kSunBlock * nu * nm * nw, 0.0f), dL(kSunBlock * 2 * nu * nw, 0.0f),
        acc(kSub * nw);
    const size_t sb = nm * nu * nw, tb = nu * nm * nw, db = 2 * nu * nw;
    for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
      const size_t ri = idx / nsb, s0 = (idx % nsb) * kSunBlock, s1 = std::min(ns, s0 + kSunBlock), nb = s1 - s0;
      const size_t nsub = (nb + kSub - 1) / kSub;
      const K* G = &Gall[ri * sk.modal_floats];
      // Analysis: S[b][m][k2] = sum_q L(k2, q) cos(m theta_q); the end differences dL.
      for (size_t b = 0; b < nb; ++b) {
        const float* lin = &Lin[((ri * ns + s0 + b) * nd) * nw];
        for (size_t k2 = 0; k2 < nu; ++k2) {
          ModalAnalysis(&lin[k2 * nphi * nw], sk.cos_mq.data(), nm, nphi, nw, &S[b * sb + k2 * nw], nu * nw);
          if (!has_ends) continue;
          // L(0) - L(1) at the near end, L(nphi - 1) - L(nphi - 2) at the far one (the mirror).
          const float* l0 = &lin[k2 * nphi * nw];
          const float* l1 = &lin[(k2 * nphi + nphi - 2) * nw];
          float* d0 = &dL[b * db + k2 * nw];
          float* d1 = &dL[b * db + (nu + k2) * nw];
          for (size_t w = 0; w < nw; ++w) d0[w] = l0[w] - l0[nw + w];
          for (size_t w = 0; w < nw; ++w) d1[w] = l1[nw + w] - l1[w];
        }
      }
      // Modes: T[b][k][m] = sum_k2 G_m(k, k2) S[b][m][k2].
      for (size_t m = 0; m < nm; ++m) {
        for (size_t k = 0; k < nu; ++k) {
          for (size_t u = 0; u < nsub; ++u) {
            ModalBlock4(&G[(m * nu + k) * nu * nw], nw, &S[u * kSub * sb + m * nu * nw], nw, sb, nu, nw, acc.data());
            for (size_t b = 0; b < kSub; ++b) std::copy_n(&acc[b * nw], nw, &T[(u * kSub + b) * tb + (k * nm + m) * nw]);
          }
        }
      }
      // Synthesis and the end columns: J per unit sigma_s*, as the kernels are (kernel.h).
      for (size_t k = 0; k < nu; ++k) {
        for (size_t q = 0; q < nphi; ++q) {
          for (size_t u = 0; u < nsub; ++u) {
            ModalSynthesis4(&sk.cos_mq[q], nphi, &T[u * kSub * tb + k * nm * nw], tb, nm, nw, acc.data());
            if (has_ends) {
              for (size_t e = 0; e < 2; ++e) {
                const size_t qe = e == 0 ? q : nphi - 1 - q;
                const K* Dv = &Dall[ri * sk.end_floats + ((k * nphi + qe) * nu) * nw];
                ModalBlock4Add(Dv, nw, &dL[u * kSub * db + e * nu * nw], nw, db, nu, nw, acc.data());
              }
            }
            for (size_t b = 0; b < kSub && u * kSub + b < nb; ++b) {
              std::copy_n(&acc[b * nw], nw, &(*Jout)[(((ri * ns + s0 + u * kSub + b) * nd) + k * nphi + q) * nw]);
            }
          }
        }
      }
    }
  });
}

void ScatterModal(const KernelContext& kc, const ScatterKernels& sk, const Table& Lin, Table* Jout) {
  if (sk.half) ScatterModalAs(kc, sk, sk.modal_half.data(), sk.end_half.data(), Lin, Jout);
  else ScatterModalAs(kc, sk, sk.modal_kernels.data(), sk.end_kernels.data(), Lin, Jout);
}

}  // namespace skybake::orders
