// The noise primitives (noise/lattice.h, noise/hash.h): exact periodicity, Perlin's construction
// (zero on lattice points, C1 across cell faces), Worley F1 against brute force, hash streams.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "noise/hash.h"
#include "noise/lattice.h"

using namespace skybake::noise;

TEST(Hash, StreamsAndCoordinatesAreDistinct) {
  // Distinct keys/coordinates give distinct 64-bit hashes over a small cube (a collision among
  // 4096 values of a 64-bit hash would have probability ~1e-12).
  std::set<uint64_t> seen;
  for (int a = 0; a < 16; ++a)
    for (int b = 0; b < 16; ++b)
      for (int c = 0; c < 16; ++c) seen.insert(Hash(StreamKey(1, 0), a, b, c));
  EXPECT_EQ(seen.size(), 4096u);
  EXPECT_NE(Hash(7, 1, 2), Hash(7, 2, 1));
  EXPECT_NE(StreamKey(1, 0, 0), StreamKey(1, 0, 1));
  EXPECT_NE(StreamKey(1, 0), StreamKey(2, 0));
  // UnitDouble is in [0, 1) and its mean over many hashes is 1/2 (+- 4 sigma, sigma = 1/sqrt(12 n)).
  double sum = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = UnitDouble(Hash(3, i));
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
  }
  EXPECT_NEAR(sum / n, 0.5, 4.0 / std::sqrt(12.0 * n));
}

TEST(PerlinNoise, FadeCurveIsC2) {
  // s(0) = 0, s(1) = 1, s'(0) = s'(1) = s''(0) = s''(1) = 0 (Perlin 2002 §2), by finite differences.
  const double h = 1e-4;
  EXPECT_EQ(Fade(0.0), 0.0);
  EXPECT_EQ(Fade(1.0), 1.0);
  EXPECT_NEAR((Fade(h) - Fade(0.0)) / h, 0.0, 1e-6);
  EXPECT_NEAR((Fade(1.0) - Fade(1.0 - h)) / h, 0.0, 1e-6);
  EXPECT_NEAR((Fade(2 * h) - 2 * Fade(h) + Fade(0.0)) / (h * h), 0.0, 1e-2);
}

TEST(PerlinNoise, ZeroOnLatticePointsAndExactlyPeriodic) {
  PeriodicGradientNoise3 n(5, StreamKey(11, 0));
  for (int x = -5; x <= 10; ++x) EXPECT_EQ(n(x, 2, 3), 0.0);
  // n(p + 5 e_k) = n(p): the same lattice corners and fractions, so equal up to the rounding of
  // p + 5 (1e-15 relative).
  for (int t = 0; t < 200; ++t) {
    const double x = UnitDouble(Hash(1, t)) * 5, y = UnitDouble(Hash(2, t)) * 5, z = UnitDouble(Hash(3, t)) * 5;
    const double v = n(x, y, z);
    EXPECT_NEAR(n(x + 5, y, z), v, 1e-12);
    EXPECT_NEAR(n(x, y - 5, z), v, 1e-12);
    EXPECT_NEAR(n(x, y, z + 10), v, 1e-12);
    EXPECT_LT(std::fabs(v), 1.1);  // the 12-gradient noise stays within about +-1
  }
}

TEST(PerlinNoise, ContinuousValueAndGradientAcrossCellFaces) {
  // Across the face x = 3 the one-sided values and slopes agree (C1; quintic fade makes it C2).
  PeriodicGradientNoise3 n(8, StreamKey(5, 1));
  const double e = 1e-7, h = 1e-4;
  for (int t = 0; t < 50; ++t) {
    const double y = UnitDouble(Hash(4, t)) * 8, z = UnitDouble(Hash(5, t)) * 8;
    EXPECT_NEAR(n(3 - e, y, z), n(3 + e, y, z), 1e-6);
    const double left = (n(3 - e, y, z) - n(3 - e - h, y, z)) / h;
    const double right = (n(3 + e + h, y, z) - n(3 + e, y, z)) / h;
    EXPECT_NEAR(left, right, 5e-3);
  }
}

TEST(WorleyNoise, NeighbourhoodSearchEqualsBruteForce) {
  // The 3x3x3 (then 5x5x5) search against every point of the tile and its periodic images, for
  // small periods (where neighbours wrap onto the same cells) and full jitter.
  for (int period : {1, 2, 3, 4, 7}) {
    PeriodicWorley3 w(period, 1.0, StreamKey(9, static_cast<uint64_t>(period)));
    for (int t = 0; t < 300; ++t) {
      const double x = (UnitDouble(Hash(10, t)) - 0.25) * period * 1.5;
      const double y = (UnitDouble(Hash(11, t)) - 0.25) * period * 1.5;
      const double z = (UnitDouble(Hash(12, t)) - 0.25) * period * 1.5;
      ASSERT_NEAR(w.F1(x, y, z), w.F1BruteForce(x, y, z), 1e-12) << "period " << period;
    }
  }
}

TEST(WorleyNoise, PeriodicAndZeroAtFeaturePoints) {
  PeriodicWorley3 w(6, 1.0, StreamKey(2, 2));
  for (int t = 0; t < 100; ++t) {
    const double x = UnitDouble(Hash(1, t)) * 6, y = UnitDouble(Hash(2, t)) * 6, z = UnitDouble(Hash(3, t)) * 6;
    EXPECT_NEAR(w.F1(x + 6, y, z), w.F1(x, y, z), 1e-12);
    EXPECT_NEAR(w.F1(x, y + 12, z - 6), w.F1(x, y, z), 1e-12);
    EXPECT_LE(w.F1(x, y, z), std::sqrt(3.0));  // the own cell's point is within a cell diagonal
  }
  // Jitter 0: points at cell centres, so F1 at a centre is 0 and at a cell corner sqrt(3)/2.
  PeriodicWorley3 grid(4, 0.0, StreamKey(1, 1));
  EXPECT_NEAR(grid.F1(2.5, 0.5, 3.5), 0.0, 1e-15);
  EXPECT_NEAR(grid.F1(1.0, 2.0, 3.0), std::sqrt(3.0) / 2.0, 1e-15);
}

TEST(GradientNoise2, ZeroOnLatticeBoundedAndNotPeriodic) {
  GradientNoise2 n(StreamKey(4, 4));
  EXPECT_EQ(n(3.0, -7.0), 0.0);
  EXPECT_EQ(n(1e9, 1e9), 0.0);  // int64 lattice far from the origin
  double maxabs = 0.0;
  int equal_after_shift = 0;
  for (int t = 0; t < 2000; ++t) {
    const double x = UnitDouble(Hash(1, t)) * 100, y = UnitDouble(Hash(2, t)) * 100;
    maxabs = std::max(maxabs, std::fabs(n(x, y)));
    // No short period: shifting by 256 or 65536 cells changes the value.
    equal_after_shift += std::fabs(n(x + 256, y) - n(x, y)) < 1e-12;
    equal_after_shift += std::fabs(n(x, y + 65536) - n(x, y)) < 1e-12;
  }
  // N-dimensional gradient noise with unit gradients is bounded by sqrt(N/4) (reached at a cell
  // centre with every gradient pointing away from its corner): sqrt(1/2) in 2D.
  EXPECT_LE(maxabs, std::sqrt(0.5) + 1e-12);
  EXPECT_GT(maxabs, 0.3);
  EXPECT_EQ(equal_after_shift, 0);
}
