// The transport by families: all cells of a family (radius node, view node) share each step's
// point and so its 4 radius/view corners. Per step, the radius/view blend of J is formed once for
// every sun and azimuth node (a slab of ns x nphi x nw, which stays in cache), and each cell then
// blends 4 sun/azimuth corners of the slab: 4 + 4 products per wavelength per cell instead of 16,
// and the cells' reads go to the slab instead of 16 scattered table rows. The same sums in another
// order: the result differs from TransportCells by float rounding
// (MethodOrders.SplitGatherIsTheCellGather).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "transport/orders/simd.h"
#include "transport/orders/transport.h"

namespace skybake::orders {

namespace {

// One family's working set: slab[(s * nphi + q) * nw + w], the sum over the 4 radius/view
// corners; lo / hi: the lower and the upper radius's 2 corners apart (twilight's log-linear
// factor), for s >= loglin_first; acc: the family's cells; pts: their positions at a step; nu:
// their scattering cosines.
struct FamilyScratch {
  std::vector<float> slab, lo, hi, acc, eg;
  std::vector<SunAzimuth> pts;
  std::vector<double> nu;
  FamilyScratch(size_t plane, size_t nw)
      : slab(plane * nw), lo(plane * nw), hi(plane * nw), acc(plane * nw), eg(nw), pts(plane), nu(plane) {}
};

// The scattering cosines of the family's cells, for the positions computed per step.
void FamilyGeometry(const TransportContext& tc, size_t ri, size_t k, FamilyScratch* x) {
  const size_t ns = tc.nodes->ns, nphi = static_cast<size_t>(tc.nodes->nphi);
  double mu;
  for (size_t si = 0; si < ns; ++si) {
    for (size_t q = 0; q < nphi; ++q) tc.nodes->CellGeometry(ri, si, k, q, &mu, &x->nu[si * nphi + q]);
  }
}

// The cells' sun/azimuth positions at step m into x->pts, and the sun nodes [*s_lo, *s_hi] they read.
void StepPositions(const TransportContext& tc, const Family& f, size_t m, size_t ri, size_t k, FamilyScratch* x, size_t* s_lo,
                   size_t* s_hi) {
  const size_t ns = tc.nodes->ns, nphi = static_cast<size_t>(tc.nodes->nphi), plane = tc.plane;
  if (tc.Stored(ri)) {
    const PackedSunAzimuth* from = &tc.sun_az[tc.PositionIndex(ri, k, m, 0, 0)];  // the family's cells at step m, in order
    for (size_t cell = 0; cell < plane; ++cell) x->pts[cell] = UnpackSunAzimuth(from[cell]);
  } else {
    for (size_t si = 0; si < ns; ++si) {
      for (size_t q = 0; q < nphi; ++q) x->pts[si * nphi + q] = tc.ComputedStepPosition(f, m, ri, si, x->nu[si * nphi + q]);
    }
  }
  *s_lo = ns, *s_hi = 0;
  for (size_t cell = 0; cell < plane; ++cell) {
    const SunAzimuth& p = x->pts[cell];
    if (p.si == kNoSun) continue;
    *s_lo = std::min<size_t>(*s_lo, p.si);
    *s_hi = std::max<size_t>(*s_hi, std::min<size_t>(p.si + 1, ns - 1));
  }
}

// The slab of step m: J blended over the step's 4 radius/view corners for sun nodes s_lo..s_hi.
void BlendSlab(const TransportContext& tc, const Table& Jin, const Family::Corners& c, size_t s_lo, size_t s_hi, FamilyScratch* x) {
  const size_t nw = tc.md->nw, nu = tc.nodes->nu, nphi = static_cast<size_t>(tc.nodes->nphi);
  for (size_t s = s_lo; s <= s_hi; ++s) {
    const size_t so = s * nu * nphi;
    const float* v[4];
    for (int a = 0; a < 4; ++a) v[a] = &Jin[(c.off[a] + so) * nw];
    const size_t n = nphi * nw;
    float* out = &x->slab[s * n];
    if (s < tc.loglin_first) {
      Gather16(v, c.w, 0, 4, n, out);
    } else {
      GatherLoHi(v, c.w, n, &x->lo[s * n], &x->hi[s * n], out);
    }
  }
}

// Each cell's 4 sun/azimuth corners of the slab, times the step's weight gm, added to its acc.
void AccumulateCells(const TransportContext& tc, const std::vector<float>& cfac, const float* gm, size_t r0, FamilyScratch* x) {
  const size_t nw = tc.md->nw, nphi = static_cast<size_t>(tc.nodes->nphi), plane = tc.nodes->ns * nphi;
  for (size_t cell = 0; cell < plane; ++cell) {
    const SunAzimuth& p = x->pts[cell];
    if (p.si == kNoSun) continue;
    const size_t so = static_cast<size_t>(p.si) * nphi + p.q0;
    float ws[4];
    size_t sofs[4];
    SunAzimuthCorners(p, so, nphi, ws, sofs);
    const bool loglin = p.si >= tc.loglin_first && p.ts > 0.0f;
    float* a = &x->acc[cell * nw];
    if (!loglin) {
      const float* v[4] = {&x->slab[sofs[0] * nw], &x->slab[sofs[1] * nw], &x->slab[sofs[2] * nw], &x->slab[sofs[3] * nw]};
      AccumulateCorners4(v, ws, gm, nw, a);
    } else {
      const float* vl[4] = {&x->lo[sofs[0] * nw], &x->lo[sofs[1] * nw], &x->lo[sofs[2] * nw], &x->lo[sofs[3] * nw]};
      const float* vh[4] = {&x->hi[sofs[0] * nw], &x->hi[sofs[1] * nw], &x->hi[sofs[2] * nw], &x->hi[sofs[3] * nw]};
      const float *c0, *c1;
      float tb;
      LogLinBins(tc, cfac, p, r0, &c0, &c1, &tb);
      AccumulateCorners4LogLin(vl, vh, ws, c0, c1, tb, gm, nw, a);
    }
  }
}

// The family's cells: the ground's reflection of E where the ray ends on it, stored into Lout.
void StoreFamily(const TransportContext& tc, const Family& f, size_t ri, size_t k, const std::vector<float>& E, FamilyScratch* x,
                 Table* Lout) {
  const Nodes& nodes = *tc.nodes;
  const size_t nw = tc.md->nw, nphi = static_cast<size_t>(nodes.nphi);
  const double r = nodes.radius[ri];
  for (size_t si = 0; si < nodes.ns; ++si) {
    const double ts = nodes.sun_theta_rad[si];
    for (size_t q = 0; q < nphi; ++q) {
      float* a = &x->acc[(si * nphi + q) * nw];
      if (f.ground) {
        double mu, nu;
        nodes.CellGeometry(ri, si, k, q, &mu, &nu);
        AddGroundReflection(nodes, *tc.md, f, r, ts, nu, E, x->eg.data(), a);
      }
      std::copy(a, a + nw, &(*Lout)[nodes.Cell(ri, si, k, q) * nw]);
    }
  }
}

}  // namespace

void TransportSplit(const TransportContext& tc, const Table& Jin, const Table& Lin, Table* Lout) {
  const Nodes& nodes = *tc.nodes;
  const size_t nw = tc.md->nw, nu = nodes.nu, nr = nodes.radius.size();
  std::vector<float> E;
  GroundIrradiance(nodes, tc.s->ndn, Lin, &E);
  const std::vector<float> cfac = LogLinFactors(tc, Jin);
  const size_t plane = nodes.ns * static_cast<size_t>(nodes.nphi);  // cells of one family
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nu, 1), [&](const tbb::blocked_range<size_t>& rg) {
    FamilyScratch x(plane, nw);
    for (size_t fi = rg.begin(); fi != rg.end(); ++fi) {
      const size_t ri = fi / nu, k = fi % nu;
      const Family& f = (*tc.fam)[fi];
      std::fill(x.acc.begin(), x.acc.end(), 0.0f);
      if (!tc.Stored(ri)) FamilyGeometry(tc, ri, k, &x);
      for (size_t m = 0; m < f.t.size(); ++m) {
        size_t s_lo, s_hi;
        StepPositions(tc, f, m, ri, k, &x, &s_lo, &s_hi);
        if (s_lo > s_hi) continue;
        BlendSlab(tc, Jin, f.rc[m], s_lo, s_hi, &x);
        AccumulateCells(tc, cfac, &f.g[m * nw], f.rv[m].ri, &x);
      }
      StoreFamily(tc, f, ri, k, E, &x, Lout);
    }
  });
}

}  // namespace skybake::orders
