#include "transport/orders/transport.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "atmosphere/ray_sphere.h"
#include "transport/orders/simd.h"

namespace skybake::orders {

TransportContext MakeTransportContext(const AtmosphereModel& m, const Medium& md, const Nodes& nodes, const OrdersSettings& s,
                                      const std::vector<Family>& fam) {
  TransportContext tc;
  tc.m = &m, tc.md = &md, tc.nodes = &nodes, tc.s = &s, tc.fam = &fam;
  tc.nd = nodes.nu * static_cast<size_t>(s.nphi);
  tc.nt = static_cast<size_t>(s.nt), tc.plane = nodes.ns * static_cast<size_t>(s.nphi);
  const size_t per_radius = nodes.ns * tc.nd * tc.nt;  // positions per radius node
  tc.stored_radii = PositionsPackable(nodes.ns, static_cast<size_t>(s.nphi))
                        ? std::min(nodes.radius.size(), (static_cast<size_t>(s.step_positions_mib) << 20) / (per_radius * sizeof(PackedSunAzimuth)))
                        : 0;
  tc.sun_az.resize(tc.stored_radii * per_radius);
  for (double ts : nodes.sun_theta_rad) tc.cos_sun.push_back(std::cos(ts));
  tc.loglin_first = nodes.ns;
  for (size_t si = 0; si + 1 < nodes.ns; ++si) {
    if (s.sun_deg[si] >= s.loglin_from_deg - 1e-9) {
      tc.loglin_first = si;
      break;
    }
  }
  return tc;
}

SunAzimuth TransportContext::ComputedStepPosition(const Family& f, size_t step, size_t ri, size_t si, double nu_s) const {
  return QuantizeSunAzimuth(StepSunAzimuth(*nodes, s->azimuth_even, f, step, nodes->radius[ri], cos_sun[si], nu_s));
}

void GroundIrradiance(const Nodes& nodes, int ndn, const Table& L, std::vector<float>* E) {
  const size_t nw = nodes.nw, ns = nodes.ns, nu = nodes.nu, nphi = static_cast<size_t>(nodes.nphi);
  const double R = nodes.bottom_radius_m;
  E->assign(ns * nw, 0.0f);
  for (size_t si = 0; si < ns; ++si) {
    for (size_t k = static_cast<size_t>(ndn); k < nu; ++k) {
      const double mu = nodes.ViewMu(k, R), dmu = nodes.ViewWidth(k, R);
      for (size_t q = 0; q < nphi; ++q) {
        const float wgt = static_cast<float>(mu * dmu * 2.0 * kPi / nodes.nphi);
        const float* v = &L[nodes.Cell(0, si, k, q) * nw];
        for (size_t w = 0; w < nw; ++w) (*E)[si * nw + w] += wgt * v[w];
      }
    }
  }
}

void InterpE(const Nodes& nodes, const std::vector<float>& E, double theta_s, float* out) {
  const size_t nw = nodes.nw;
  if (theta_s > nodes.sun_theta_rad.back()) {
    std::fill(out, out + nw, 0.0f);
    return;
  }
  const Lerp l = Locate(nodes.sun_loc, theta_s);
  for (size_t w = 0; w < nw; ++w) {
    out[w] = static_cast<float>(E[l.i * nw + w] * (1.0 - l.t) + E[(l.i + 1) * nw + w] * l.t);
  }
}

std::vector<float> LogLinFactors(const TransportContext& tc, const Table& Jin) {
  const size_t nw = tc.md->nw, ns = tc.nodes->ns, nr = tc.nodes->radius.size(), nd = tc.nd, first = tc.loglin_first;
  std::vector<float> cfac;
  if (first >= ns) return cfac;
  cfac.assign(nr * ns * (kLogBins + 1) * nw, 1.0f);
  tbb::parallel_for(size_t{0}, nr, [&](size_t ri) {
    std::vector<double> g(ns * nw, 0.0);
    for (size_t si = first; si < ns; ++si) {
      for (size_t i = 0; i < nd; ++i) {
        const float* v = &Jin[(((ri * ns + si) * nd) + i) * nw];
        for (size_t w = 0; w < nw; ++w) g[si * nw + w] += v[w];
      }
    }
    for (size_t si = first; si + 1 < ns; ++si) {
      for (size_t b = 0; b <= kLogBins; ++b) {
        const double t = static_cast<double>(b) / kLogBins;
        float* c = &cfac[((ri * ns + si) * (kLogBins + 1) + b) * nw];
        for (size_t w = 0; w < nw; ++w) {
          const double a = g[si * nw + w], bb = g[(si + 1) * nw + w];
          const double lin = (1.0 - t) * a + t * bb;
          c[w] = a > 0.0 && bb > 0.0 && lin > 0.0 ? static_cast<float>(a * std::pow(bb / a, t) / lin) : 1.0f;
        }
      }
    }
  });
  return cfac;
}

void AddGroundReflection(const Nodes& nodes, const Medium& md, const Family& f, double r, double ts, double nu,
                         const std::vector<float>& E, float* eg, float* acc) {
  const double mus_g = SunMuAt(r, std::cos(ts), nu, f.d, nodes.bottom_radius_m);
  InterpE(nodes, E, std::acos(ClampCosine(mus_g)), eg);
  for (size_t w = 0; w < md.nw; ++w) acc[w] += f.trans_end[w] * static_cast<float>(md.albedo[w] / kPi) * eg[w];
}

void LogLinBins(const TransportContext& tc, const std::vector<float>& cfac, const SunAzimuth& p, size_t r0, const float** c0,
                const float** c1, float* tb) {
  const size_t nw = tc.md->nw, ns = tc.nodes->ns, nr = tc.nodes->radius.size();
  const float fb = p.ts * kLogBins;
  const size_t b0 = std::min(static_cast<size_t>(fb), kLogBins - 1);
  *tb = fb - static_cast<float>(b0);
  const size_t r1 = std::min(r0 + 1, nr - 1);
  *c0 = &cfac[((r0 * ns + p.si) * (kLogBins + 1) + b0) * nw];
  *c1 = &cfac[((r1 * ns + p.si) * (kLogBins + 1) + b0) * nw];
}

void LogBlend(const TransportContext& tc, const std::vector<float>& cfac, const SunAzimuth& p, size_t r0, float* jlo, const float* jhi) {
  const size_t nw = tc.md->nw;
  const float *c00, *c10;
  float tb;
  LogLinBins(tc, cfac, p, r0, &c00, &c10, &tb);
  for (size_t w = 0; w < nw; ++w) {
    const float f0 = c00[w] + (c00[w + nw] - c00[w]) * tb, f1 = c10[w] + (c10[w + nw] - c10[w]) * tb;
    jlo[w] = jlo[w] * f0 + jhi[w] * f1;
  }
}

// The 16-corner gather of J (radius x view x sun x azimuth) cell by cell: offsets and weights
// split into the step's radius/view part (per family) and its sun/azimuth part (per cell).
void TransportCells(const TransportContext& tc, const Table& Jin, const Table& Lin, Table* Lout) {
  const Nodes& nodes = *tc.nodes;
  const size_t nw = tc.md->nw, ns = nodes.ns, nu = nodes.nu, nphi = static_cast<size_t>(nodes.nphi), nr = nodes.radius.size();
  std::vector<float> E;
  GroundIrradiance(nodes, tc.s->ndn, Lin, &E);
  const std::vector<float> cfac = LogLinFactors(tc, Jin);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * ns * nu, 4), [&](const tbb::blocked_range<size_t>& rg) {
    std::vector<float> acc(nw), jv(nw), jv2(nw), eg(nw);
    for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
      const size_t ri = idx / (ns * nu), si = (idx / nu) % ns, k = idx % nu;
      const Family& f = (*tc.fam)[ri * nu + k];
      const double r = nodes.radius[ri], ts = nodes.sun_theta_rad[si];
      for (size_t q = 0; q < nphi; ++q) {
        double mu, nu_s;
        nodes.CellGeometry(ri, si, k, q, &mu, &nu_s);
        std::fill(acc.begin(), acc.end(), 0.0f);
        for (size_t m = 0; m < f.t.size(); ++m) {
          const SunAzimuth p = tc.StepPosition(f, m, ri, si, k, q, nu_s);
          if (p.si == kNoSun) continue;
          const size_t so = (static_cast<size_t>(p.si) * nu) * nphi + p.q0;
          float ws[4];
          size_t sofs[4];
          SunAzimuthCorners(p, so, nu * nphi, ws, sofs);
          const Family::Corners& c = f.rc[m];
          const float* v[16];
          float wv[16];
          for (int a = 0; a < 4; ++a) {
            for (int b = 0; b < 4; ++b) {
              v[4 * a + b] = &Jin[(c.off[a] + sofs[b]) * nw];
              wv[4 * a + b] = c.w[a] * ws[b];
            }
          }
          float* jvp = jv.data();
          // The 16 products summed in one pass per wavelength, in corner order (a term of
          // weight 0 adds +-0: the same sums as skipping it); twilight: the upper radius
          // corners accumulate apart, for their own factor C.
          const bool loglin = p.si >= tc.loglin_first && p.ts > 0.0f;
          if (!loglin) {
            Gather16(v, wv, 0, 16, nw, jvp);
          } else {
            Gather16(v, wv, 0, 8, nw, jvp);
            Gather16(v, wv, 8, 16, nw, jv2.data());
          }
          if (loglin) LogBlend(tc, cfac, p, f.rv[m].ri, jvp, jv2.data());
          const float* gm = &f.g[m * nw];
          for (size_t w = 0; w < nw; ++w) acc[w] += gm[w] * jvp[w];
        }
        if (f.ground) AddGroundReflection(nodes, *tc.md, f, r, ts, nu_s, E, eg.data(), acc.data());
        std::copy(acc.begin(), acc.end(), &(*Lout)[nodes.Cell(ri, si, k, q) * nw]);
      }
    }
  });
}

void Transport(const TransportContext& tc, const Table& Jin, const Table& Lin, Table* Lout) {
  if (tc.s->gather_split) TransportSplit(tc, Jin, Lin, Lout);
  else TransportCells(tc, Jin, Lin, Lout);
}

}  // namespace skybake::orders
