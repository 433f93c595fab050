#include "transport/orders/kernel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace skybake::orders {

namespace {

// The kernel integrated against the interpolation's basis: J(v_i) = int P(v_i . w) L(w) dw
// with L(w) = sum_j L_j h_j(w), h_j the weight the table lookup gives node j at w (linear in
// the view-node index f, and AzimuthBlend in the azimuth; both mirror halves of the azimuth).
// Integrated by the midpoint rule on n sub-intervals of every view interval (in f, so as dense
// as the nodes) and 2n of every azimuth interval. With the phase sampled at the nodes instead,
// a node stands for its whole cell: at the zenith node (a cap ~9 deg across) the aerosol lobe,
// ~5 deg wide after truncation at 3 deg, is counted as filling the cap, and the row's
// normalisation then takes that excess from every other direction (hazed, sun 70 deg, order 2
// at the zenith -1.3 %, -2.4 % with 3 deg truncation; with this kernel +0.3 %).
void BuildHatKernel(const KernelContext& kc, double r, const std::vector<float>& mix, const std::vector<double>& vmu,
                    const std::vector<double>& vsn, float* kernel) {
  const OrdersSettings& s = *kc.s;
  const size_t nw = kc.md->nw, nphi = static_cast<size_t>(s.nphi), nd = kc.nd;
  const int sub = s.kernel_sub;
  const size_t per = 2 * static_cast<size_t>(sub), na = nphi * per;
  const double u = kPi / static_cast<double>(na);
  std::vector<size_t> aq(na);
  std::vector<float> atq(na);
  for (size_t a = 0; a < na; ++a) {
    size_t q0;
    atq[a] = static_cast<float>(kc.nodes->AzimuthBlend((a + 0.5) * u, s.azimuth_even, &q0));
    aq[a] = q0;
  }
  std::vector<float> row(nphi * nw);
  kc.ForEachViewSubsample(r, mix, vmu, vsn, [&](size_t k, const size_t* kn, const double* wk, double dmu, const std::vector<float>& pm) {
    for (size_t q = 0; q < nphi; ++q) {
      // The row of output node (k, q) over the azimuth nodes, for this view sub-interval.
      std::fill(row.begin(), row.end(), 0.0f);
      const long qa = static_cast<long>(q * per + static_cast<size_t>(sub));
      for (size_t a = 0; a < na; ++a) {
        const long dlt = qa - static_cast<long>(a);
        const size_t md = static_cast<size_t>(dlt >= 1 ? dlt - 1 : -dlt), ms = static_cast<size_t>(qa) + a;
        const float* pd = &pm[md * nw];
        const float* ps = &pm[ms * nw];
        const float w1 = atq[a], w0 = 1.0f - w1;
        float* r0 = &row[aq[a] * nw];
        float* r1 = r0 + nw;
        for (size_t w = 0; w < nw; ++w) {
          const float v = pd[w] + ps[w];
          r0[w] += w0 * v;
          r1[w] += w1 * v;
        }
      }
      for (int x = 0; x < 2; ++x) {
        const float wgt = static_cast<float>(wk[x] * dmu * u);
        if (wgt == 0.0f) continue;
        float* out = &kernel[((k * nphi + q) * nd + kn[x] * nphi) * nw];
        for (size_t e = 0; e < nphi * nw; ++e) out[e] += wgt * row[e];
      }
    }
  });
}

// J_n = K L_{n-1} at radius node ri for the sun nodes of block sb (of kSunBlock): each kernel
// element loaded is used for 4 sun nodes (the product is load-bound otherwise).
constexpr size_t kSunBlock = 4;
void ApplyMatrix(const KernelContext& kc, const Table& Lin, size_t ri, size_t sb, const float* kernel, Table* Jout) {
  const size_t nw = kc.md->nw, ns = kc.nodes->ns, nd = kc.nd;
  const size_t s0 = sb * kSunBlock, s1 = std::min(ns, s0 + kSunBlock);
  for (size_t i = 0; i < nd; ++i) {
    float* jo[kSunBlock];
    const float* lv[kSunBlock];
    for (size_t b = 0; b < kSunBlock; ++b) {
      const size_t si = std::min(s0 + b, s1 - 1);  // a short last block repeats its last node (not stored twice)
      jo[b] = &(*Jout)[(((ri * ns + si) * nd) + i) * nw];
      lv[b] = &Lin[((ri * ns + si) * nd) * nw];
    }
    float acc[kSunBlock][64];
    for (size_t w0 = 0; w0 < nw; w0 += 64) {
      const size_t wn = std::min<size_t>(64, nw - w0);
      for (size_t b = 0; b < kSunBlock; ++b) std::fill(acc[b], acc[b] + wn, 0.0f);
      for (size_t j = 0; j < nd; ++j) {
        const float* kv = &kernel[(i * nd + j) * nw + w0];
        for (size_t b = 0; b < kSunBlock; ++b) {
          const float* l = lv[b] + j * nw + w0;
          for (size_t w = 0; w < wn; ++w) acc[b][w] += kv[w] * l[w];
        }
      }
      // Stored per unit scattering coefficient (kernel.h).
      for (size_t b = 0; b < s1 - s0; ++b) {
        for (size_t w = 0; w < wn; ++w) {
          const double st = kc.ssc_total[ri * nw + w0 + w];
          jo[b][w0 + w] = st > 0.0 ? static_cast<float>(acc[b][w] / st) : 0.0f;
        }
      }
    }
  }
}

}  // namespace

KernelContext MakeKernelContext(const Medium& md, const Nodes& nodes, const OrdersSettings& s) {
  KernelContext kc;
  kc.md = &md;
  kc.nodes = &nodes;
  kc.s = &s;
  kc.nd = nodes.nu * static_cast<size_t>(s.nphi);
  const size_t nr = nodes.radius.size(), nw = md.nw;
  kc.ssc_total.assign(nr * nw, 0.0);
  for (size_t ri = 0; ri < nr; ++ri) {
    std::vector<float> ssc(nw);
    for (size_t c = 0; c < md.nc; ++c) {
      md.SigmaS(c, nodes.radius[ri] - nodes.bottom_radius_m, true, ssc.data());
      for (size_t w = 0; w < nw; ++w) kc.ssc_total[ri * nw + w] += ssc[w];
    }
  }
  return kc;
}

std::vector<float> KernelContext::Mixture(size_t ri) const {
  constexpr int kPhaseGrid = Medium::kPhaseGrid;
  const size_t nw = md->nw;
  std::vector<float> mix(static_cast<size_t>(kPhaseGrid) * nw, 0.0f), ssc(nw);
  for (size_t c = 0; c < md->nc; ++c) {
    md->SigmaS(c, nodes->radius[ri] - nodes->bottom_radius_m, true, ssc.data());
    for (int g = 0; g < kPhaseGrid; ++g) {
      for (size_t w = 0; w < nw; ++w) mix[static_cast<size_t>(g) * nw + w] += ssc[w] * md->phase_star[(c * kPhaseGrid + static_cast<size_t>(g)) * nw + w];
    }
  }
  return mix;
}

void KernelContext::MixtureAt(const std::vector<float>& mix, double mu, float scale, float* out) const {
  constexpr int kPhaseGrid = Medium::kPhaseGrid;
  const size_t nw = md->nw;
  const double g = (std::clamp(mu, -1.0, 1.0) + 1.0) * 0.5 * (kPhaseGrid - 1);
  const size_t gi = std::min(static_cast<size_t>(g), static_cast<size_t>(kPhaseGrid - 2));
  const float t = static_cast<float>(g - static_cast<double>(gi));
  const float* a = &mix[gi * nw];
  const float* b = &mix[(gi + 1) * nw];
  for (size_t w = 0; w < nw; ++w) out[w] += scale * (a[w] + (b[w] - a[w]) * t);
}

ViewNodes KernelContext::ViewNodesAt(double r) const {
  const size_t nu = nodes->nu;
  ViewNodes v{std::vector<double>(nu), std::vector<double>(nu), std::vector<double>(nu)};
  for (size_t k = 0; k < nu; ++k) {
    v.mu[k] = nodes->ViewMu(k, r);
    v.sn[k] = std::sqrt(std::max(0.0, 1.0 - v.mu[k] * v.mu[k]));
    v.width[k] = nodes->ViewWidth(k, r);
  }
  return v;
}

// The (nd x nd) kernel per wavelength at radius node ri: the phase at the node pairs (both mirror
// azimuths), or the basis-integrated one (kernel_sub > 0); every row scaled to sum to sigma_s*
// (normalise: the phase function integrates to 1 over incoming directions, and point sampling of
// a peaked phase on ~200 directions misses that by a few per cent).
void BuildMatrixKernel(const KernelContext& kc, size_t ri, float* kernel) {
  const OrdersSettings& s = *kc.s;
  const size_t nw = kc.md->nw, nphi = static_cast<size_t>(s.nphi), nd = kc.nd;
  const double r = kc.nodes->radius[ri];
  const std::vector<float> mix = kc.Mixture(ri);
  std::fill(kernel, kernel + nd * nd * nw, 0.0f);
  std::vector<double> cos_dphi(nphi * nphi), cos_sphi(nphi * nphi);
  for (size_t q = 0; q < nphi; ++q) {
    for (size_t q2 = 0; q2 < nphi; ++q2) {
      const double phi = (q + 0.5) * kPi / s.nphi, phi2 = (q2 + 0.5) * kPi / s.nphi;
      cos_dphi[q * nphi + q2] = std::cos(phi - phi2);
      cos_sphi[q * nphi + q2] = std::cos(phi + phi2);
    }
  }
  const ViewNodes vn = kc.ViewNodesAt(r);
  const std::vector<double>&vmu = vn.mu, &vsn = vn.sn, &vwidth = vn.width;
  if (s.kernel_sub > 0) {
    BuildHatKernel(kc, r, mix, vmu, vsn, kernel);
  } else {
    for (size_t i = 0; i < nd; ++i) {
      const size_t k = i / nphi, q = i % nphi;
      for (size_t j = 0; j < nd; ++j) {
        const size_t k2 = j / nphi, q2 = j % nphi;
        const float wgt = static_cast<float>(vwidth[k2] * kPi / s.nphi);
        float* out = &kernel[(i * nd + j) * nw];
        const double cc = vmu[k] * vmu[k2], ss = vsn[k] * vsn[k2];
        kc.MixtureAt(mix, cc + ss * cos_dphi[q * nphi + q2], wgt, out);
        kc.MixtureAt(mix, cc + ss * cos_sphi[q * nphi + q2], wgt, out);
      }
    }
  }
  if (!s.normalise) return;
  for (size_t i = 0; i < nd; ++i) {
    std::vector<double> row(nw, 0.0);
    for (size_t j = 0; j < nd; ++j) {
      const float* kv = &kernel[(i * nd + j) * nw];
      for (size_t w = 0; w < nw; ++w) row[w] += kv[w];
    }
    std::vector<float> scale(nw, 1.0f);
    for (size_t w = 0; w < nw; ++w) scale[w] = row[w] > 0.0 ? static_cast<float>(kc.ssc_total[ri * nw + w] / row[w]) : 1.0f;
    for (size_t j = 0; j < nd; ++j) {
      float* kv = &kernel[(i * nd + j) * nw];
      for (size_t w = 0; w < nw; ++w) kv[w] *= scale[w];
    }
  }
}

void ScatterMatrix(const KernelContext& kc, const ScatterKernels& sk, const Table& Lin, Table* Jout) {
  const size_t nr = kc.nodes->radius.size(), ns = kc.nodes->ns;
  const size_t nsb = (ns + kSunBlock - 1) / kSunBlock;
  if (!sk.kernels.empty()) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nsb, 1), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
        ApplyMatrix(kc, Lin, idx / nsb, idx % nsb, &sk.kernels[(idx / nsb) * sk.kernel_floats], Jout);
      }
    });
  } else {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr, 1), [&](const tbb::blocked_range<size_t>& rg) {
      std::vector<float> kernel(sk.kernel_floats);
      for (size_t ri = rg.begin(); ri != rg.end(); ++ri) {
        BuildMatrixKernel(kc, ri, kernel.data());
        for (size_t sb = 0; sb < nsb; ++sb) ApplyMatrix(kc, Lin, ri, sb, kernel.data(), Jout);
      }
    });
  }
}

ScatterKernels BuildScatterKernels(const KernelContext& kc) {
  ScatterKernels sk;
  const size_t nr = kc.nodes->radius.size();
  sk.modal = kc.s->kernel_modal;
  sk.kernel_floats = kc.nd * kc.nd * kc.md->nw;
  if (sk.modal) {
    BuildModalKernels(kc, &sk);
  } else if (nr * sk.kernel_floats * sizeof(float) <= (size_t{768} << 20)) {
    sk.kernels.resize(nr * sk.kernel_floats);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr, 1), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t ri = rg.begin(); ri != rg.end(); ++ri) BuildMatrixKernel(kc, ri, &sk.kernels[ri * sk.kernel_floats]);
    });
  }
  return sk;
}

size_t KernelBytesPerWavelength(const Nodes& nodes, const OrdersSettings& s) {
  const size_t nr = nodes.radius.size(), nu = nodes.nu, nphi = static_cast<size_t>(s.nphi), nd = nu * nphi;
  if (!s.kernel_modal) return nr * nd * nd * sizeof(float);
  const size_t values = nphi * nu * nu + (s.kernel_sub > 0 && s.azimuth_even ? nu * nphi * nu : 0);  // G, D (BuildModalKernels)
  return nr * values * (s.kernel_half ? sizeof(uint16_t) : sizeof(float));
}

void Scatter(const KernelContext& kc, const ScatterKernels& sk, const Table& Lin, Table* Jout) {
  if (sk.modal) ScatterModal(kc, sk, Lin, Jout);
  else ScatterMatrix(kc, sk, Lin, Jout);
}

}  // namespace skybake::orders
