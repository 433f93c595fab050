// Hero-wavelength sampling: the estimator's mean is the deterministic grid quadrature.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "spectrum/xyz.h"
#include "test_data.h"

using namespace skybake;
using skybake::testing_data::LoadedCmf;
using skybake::testing_data::PlanckRadiance;

namespace {
// A smooth test spectrum: a 5778 K blackbody (W m^-2 sr^-1 nm^-1) times a gentle ripple.
std::vector<double> TestSpectrum(const WavelengthGrid& g) {
  std::vector<double> l(g.size());
  for (size_t i = 0; i < g.size(); ++i) l[i] = PlanckRadiance(g[i], 5778.0) * (1.0 + 0.3 * std::sin(g[i] / 37.0));
  return l;
}
Xyz Estimate(const HeroWavelengths& h, const std::vector<double>& l) {
  Xyz e;
  for (int k = 0; k < h.count; ++k) {
    e.X += h.weight[k].X * l[h.index[k]];
    e.Y += h.weight[k].Y * l[h.index[k]];
    e.Z += h.weight[k].Z * l[h.index[k]];
  }
  return e;
}
}  // namespace

// The K indices are equally spaced rotations: with N = 96 and K = 4, i_k = i_0 + 24 k (mod 96).
TEST(Hero, IndicesAreEquallySpacedRotations) {
  WavelengthGrid g = WavelengthGrid::Uniform(360, 835, 5);  // 96 samples
  XyzWeights w(g, LoadedCmf(Observer::kCie2006_2deg));
  for (double u : {0.0, 0.1234, 0.5, 0.99999, 1.0}) {
    HeroWavelengths h = SampleHeroWavelengths(w, u, 4);
    ASSERT_EQ(h.count, 4);
    const int i0 = std::min(95, static_cast<int>(std::floor(std::min(u, std::nextafter(1.0, 0.0)) * 96)));
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(h.index[k], (i0 + 24 * k) % 96) << "u " << u << " k " << k;
      EXPECT_EQ(h.wavelength_nm[k], g[h.index[k]]);
      EXPECT_DOUBLE_EQ(h.weight[k].Y, 24.0 * w.wy()[h.index[k]]);  // N/K = 24
    }
  }
}

// Unbiasedness, exactly: with u stratified over the N index strata, u_j = (j + 0.3)/N, every
// index appears K times, so the mean of the N estimates is the grid quadrature to rounding
// (also when K does not divide N: 95 samples, K = 4 and 7). (The offset 0.3 keeps u N + k N/K off
// the integers, where rounding would decide the floor; such u have probability zero.)
TEST(Hero, StratifiedMeanIsTheQuadratureExactly) {
  WavelengthGrid g = WavelengthGrid::Uniform(360, 830, 5);  // 95 samples
  XyzWeights w(g, LoadedCmf(Observer::kCie2006_2deg));
  const std::vector<double> l = TestSpectrum(g);
  const Xyz exact = w.Integrate(l);
  for (int k : {1, 4, 7, 16}) {
    Xyz mean;
    for (size_t j = 0; j < g.size(); ++j) {
      Xyz e = Estimate(SampleHeroWavelengths(w, (j + 0.3) / g.size(), k), l);
      mean.X += e.X / g.size();
      mean.Y += e.Y / g.size();
      mean.Z += e.Z / g.size();
    }
    EXPECT_NEAR(mean.X, exact.X, 1e-12 * exact.X) << "K = " << k;
    EXPECT_NEAR(mean.Y, exact.Y, 1e-12 * exact.Y) << "K = " << k;
    EXPECT_NEAR(mean.Z, exact.Z, 1e-12 * exact.Z) << "K = " << k;
  }
}

// Monte Carlo: 40000 independent uniform u (mt19937_64, fixed seed); the sample mean of XYZ^ is
// within 4 standard errors of the quadrature, and K = 4 has a smaller variance than K = 1.
TEST(Hero, RandomMeanWithinStatisticalError) {
  WavelengthGrid g = WavelengthGrid::Uniform(360, 830, 5);
  XyzWeights w(g, LoadedCmf(Observer::kCie1931_2deg));
  const std::vector<double> l = TestSpectrum(g);
  const Xyz exact = w.Integrate(l);
  double var_y[2] = {0, 0};
  int slot = 0;
  for (int k : {1, 4}) {
    std::mt19937_64 rng(20240611);
    const int m = 40000;
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    for (int s = 0; s < m; ++s) {
      const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;  // [0, 1)
      const Xyz e = Estimate(SampleHeroWavelengths(w, u, k), l);
      const double v[3] = {e.X, e.Y, e.Z};
      for (int c = 0; c < 3; ++c) {
        sum[c] += v[c];
        sum2[c] += v[c] * v[c];
      }
    }
    const double ex[3] = {exact.X, exact.Y, exact.Z};
    for (int c = 0; c < 3; ++c) {
      const double mean = sum[c] / m;
      const double var = (sum2[c] / m - mean * mean) * m / (m - 1);
      const double se = std::sqrt(var / m);
      EXPECT_LT(std::abs(mean - ex[c]), 4.0 * se) << "K = " << k << " channel " << c;
      EXPECT_LT(se, 0.02 * ex[c]) << "the test must be sensitive: K = " << k;
      if (c == 1) var_y[slot] = var;
    }
    ++slot;
  }
  EXPECT_LT(var_y[1], var_y[0]);
}

// K = N uses every sample once: the estimate is the quadrature for any u.
TEST(Hero, AllWavelengthsAreExact) {
  WavelengthGrid g = WavelengthGrid::Uniform(400, 700, 20);  // 16 samples
  XyzWeights w(g, LoadedCmf(Observer::kCie2006_2deg));
  const std::vector<double> l = TestSpectrum(g);
  const Xyz exact = w.Integrate(l);
  HeroWavelengths h = SampleHeroWavelengths(w, 0.377, 16);
  std::set<int> seen(h.index.begin(), h.index.begin() + h.count);
  EXPECT_EQ(seen.size(), 16u);
  EXPECT_NEAR(Estimate(h, l).Y, exact.Y, 1e-12 * exact.Y);
}

TEST(Hero, RejectsBadCounts) {
  XyzWeights w(WavelengthGrid::Uniform(400, 700, 20), LoadedCmf(Observer::kCie2006_2deg));
  EXPECT_THROW(SampleHeroWavelengths(w, 0.5, 0), InternalError);
  EXPECT_THROW(SampleHeroWavelengths(w, 0.5, kMaxHeroWavelengths + 1), InternalError);
}
