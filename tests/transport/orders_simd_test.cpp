// The transport's fused passes (transport/orders/simd.h) against the plain forms they replace:
// AccumulateCorners4 = Gather16 of the 4 corners into a buffer, then acc += gm * buffer;
// AccumulateCorners4LogLin = two such gathers (lower and upper radius), LogBlend's factors
// f = c + (c_next - c) tb applied to each, then the same sum; GatherLoHi = Gather16 of corners
// 0-1 and 2-3 and their sum. Each must give the same bits (the LUTs' bytes rest on it), for
// wavelength counts that fill 8-wide vectors, leave a remainder, or have none.
#include <gtest/gtest.h>

#include <cstddef>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "transport/orders/simd.h"

namespace skybake::orders {
namespace {

// Values over eight decades (a sky's J and its weights span them), so that any other order of
// the sums would round differently.
std::vector<float> RandomRow(std::mt19937& rng, size_t n) {
  std::uniform_real_distribution<float> mant(1.0f, 2.0f);
  std::uniform_int_distribution<int> expo(-20, 6);
  std::vector<float> v(n);
  for (float& x : v) x = std::ldexp(mant(rng), expo(rng));
  return v;
}

// 4 corner weights as SunAzimuthCorners forms them, one of them 0 now and then.
void RandomWeights(std::mt19937& rng, float ws[4]) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float ts = u(rng) < 0.2f ? 0.0f : u(rng), tq = u(rng);
  ws[0] = (1.0f - ts) * (1.0f - tq), ws[1] = (1.0f - ts) * tq, ws[2] = ts * (1.0f - tq), ws[3] = ts * tq;
}

bool SameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

const size_t kWavelengthCounts[] = {1, 5, 8, 13, 16, 21, 25, 48};

TEST(OrdersSimd, AccumulateCorners4IsTheGatherThenTheSum) {
  std::mt19937 rng(7);
  for (size_t nw : kWavelengthCounts) {
    for (int trial = 0; trial < 50; ++trial) {
      std::vector<float> rows[4] = {RandomRow(rng, nw), RandomRow(rng, nw), RandomRow(rng, nw), RandomRow(rng, nw)};
      const float* v[4] = {rows[0].data(), rows[1].data(), rows[2].data(), rows[3].data()};
      if (trial % 3 == 0) v[3] = v[0];  // a corner of weight 0 reads the first one
      float ws[4];
      RandomWeights(rng, ws);
      const std::vector<float> gm = RandomRow(rng, nw), acc0 = RandomRow(rng, nw);
      std::vector<float> j(nw), plain = acc0, fused = acc0;
      Gather16(v, ws, 0, 4, nw, j.data());
      for (size_t w = 0; w < nw; ++w) plain[w] += gm[w] * j[w];
      AccumulateCorners4(v, ws, gm.data(), nw, fused.data());
      ASSERT_TRUE(SameBits(plain, fused)) << "nw " << nw << " trial " << trial;
    }
  }
}

TEST(OrdersSimd, AccumulateCorners4LogLinIsTheGathersTheBlendThenTheSum) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), fac(0.5f, 2.0f);
  for (size_t nw : kWavelengthCounts) {
    for (int trial = 0; trial < 50; ++trial) {
      std::vector<float> lo_rows[4], hi_rows[4];
      const float *vl[4], *vh[4];
      for (int b = 0; b < 4; ++b) {
        lo_rows[b] = RandomRow(rng, nw), hi_rows[b] = RandomRow(rng, nw);
        vl[b] = lo_rows[b].data(), vh[b] = hi_rows[b].data();
      }
      float ws[4];
      RandomWeights(rng, ws);
      // Two bins of factors per radius (the bin and the next, nw apart), as LogLinBins points at.
      std::vector<float> c0(2 * nw), c1(2 * nw);
      for (float& c : c0) c = fac(rng);
      for (float& c : c1) c = fac(rng);
      const float tb = trial % 5 == 0 ? 0.0f : u(rng);
      const std::vector<float> gm = RandomRow(rng, nw), acc0 = RandomRow(rng, nw);
      std::vector<float> jlo(nw), jhi(nw), plain = acc0, fused = acc0;
      Gather16(vl, ws, 0, 4, nw, jlo.data());
      Gather16(vh, ws, 0, 4, nw, jhi.data());
      for (size_t w = 0; w < nw; ++w) {  // LogBlend's loop (transport.cpp)
        const float f0 = c0[w] + (c0[w + nw] - c0[w]) * tb, f1 = c1[w] + (c1[w + nw] - c1[w]) * tb;
        jlo[w] = jlo[w] * f0 + jhi[w] * f1;
      }
      for (size_t w = 0; w < nw; ++w) plain[w] += gm[w] * jlo[w];
      AccumulateCorners4LogLin(vl, vh, ws, c0.data(), c1.data(), tb, gm.data(), nw, fused.data());
      ASSERT_TRUE(SameBits(plain, fused)) << "nw " << nw << " trial " << trial;
    }
  }
}

TEST(OrdersSimd, GatherLoHiIsTwoGathersAndTheirSum) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (size_t n : {size_t{1}, size_t{7}, size_t{8}, size_t{25}, size_t{36 * 25}, size_t{36 * 21 + 3}}) {
    std::vector<float> rows[4] = {RandomRow(rng, n), RandomRow(rng, n), RandomRow(rng, n), RandomRow(rng, n)};
    const float* v[4] = {rows[0].data(), rows[1].data(), rows[2].data(), rows[3].data()};
    const float wv[4] = {u(rng), u(rng), u(rng), u(rng)};
    std::vector<float> lo(n), hi(n), sum(n), lo2(n), hi2(n), sum2(n);
    Gather16(v, wv, 0, 2, n, lo.data());
    Gather16(v, wv, 2, 4, n, hi.data());
    for (size_t e = 0; e < n; ++e) sum[e] = lo[e] + hi[e];
    GatherLoHi(v, wv, n, lo2.data(), hi2.data(), sum2.data());
    EXPECT_TRUE(SameBits(lo, lo2)) << n;
    EXPECT_TRUE(SameBits(hi, hi2)) << n;
    EXPECT_TRUE(SameBits(sum, sum2)) << n;
  }
}

}  // namespace
}  // namespace skybake::orders
