// optics/mie_angular.h: the batched Gram update adds every radius to every matrix element in
// the order given, so how the radii fall into batches changes no bit of the intensities.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <utility>
#include <vector>

#include "optics/mie_angular.h"
#include "optics/mie_sphere.h"
#include "optics/phase_grid.h"

namespace skybake::mie {
namespace {

// 2 x 90 radii, x = 0.3 .. 250 log-spaced, cross the batch size (32) and the 16-column tiles with
// term counts from 4 to 287 (water and a soot-like index). One accumulator takes them
// in the kernel's batches; the other is flushed after every radius (Scale(1.0) multiplies by
// one: exact), which is the plain per-radius sum G += w (x x^T + y y^T), radius by radius.
TEST(MieAngular, BatchingChangesNoBit) {
  const PhaseGrid grid = StandardPhaseGrid();
  const int max_terms = WiscombeTerms(260.0);  // the second pass ends past 250
  const AngularTables tables(grid, max_terms);
  for (Complex m : {Complex(1.33, 1e-9), Complex(1.75, 0.44)}) {
    IntensityAccumulator batched(max_terms), single(max_terms);
    MieWorkspace ws;
    MieCoefficients c;
    // Two passes, as two quadrature levels: the second starts again at small radii, so batch
    // slots that held long radii take short ones (what they held must not reach G).
    for (int level = 0; level < 2; ++level) {
      for (int r = 0; r < 90; ++r) {
        const double x = 0.3 * std::pow(250.0 / 0.3, (r + 0.5 * level) / 89.0);
        const double w = 1.0 + 0.01 * r;
        ComputeCoefficients(x, m, c, ws);
        batched.Add(c, w);
        single.Add(c, w);
        single.Scale(1.0);
      }
      batched.Scale(0.5);  // the halving of the nested trapezoid
      single.Scale(0.5);
    }
    std::vector<double> a(grid.size()), b(grid.size());
    batched.Evaluate(tables, a);
    single.Evaluate(tables, b);
    for (size_t j = 0; j < grid.size(); ++j) {
      ASSERT_GT(a[j], 0.0);
      ASSERT_EQ(std::memcmp(&a[j], &b[j], sizeof(double)), 0)
          << "m = " << m << ", angle " << j << ": " << a[j] << " vs " << b[j];
    }
  }
}

// The Gram update's kernels (4 x 16 tiles for AVX-512, 4 x 4 for AVX2 and baseline) give every
// element of the lower triangle the same operations in the same order, and the evaluation's
// (8 or 4 angles per pass) every angle: the same bits. Random
// coefficients of 1 to 77 terms (77 for the first) over 40 radii (a batch and a part), G starting non-zero; each
// kernel this CPU can run against the baseline one (the AVX-512 one is skipped on a CPU without
// it: the comparison then runs where it has it).
TEST(MieAngular, KernelsGiveTheSameBits) {
  const size_t stride = 80, terms = 77, count = 40, slot = 4 * stride;
  std::vector<double> buf(count * slot, 0.0), wbuf(count * slot, 0.0), g0(stride * stride);
  uint64_t state = 12345;
  auto uniform = [&state] {  // splitmix64 to [-1, 1)
    state += 0x9E3779B97F4A7C15ull;
    uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
  };
  for (double& v : g0) v = uniform();
  for (size_t r = 0; r < count; ++r) {
    const size_t n = r == 0 ? terms : 1 + (r * 37) % terms;  // this radius' terms; zero beyond, as Add leaves them
    const double w = 1.0 + uniform();
    for (size_t k = 0; k < 4; ++k) {
      for (size_t j = 0; j < n; ++j) {
        const double x = uniform();
        buf[r * slot + k * stride + j] = x;
        wbuf[r * slot + k * stride + j] = w * x;
      }
    }
  }
  using Kernel = void (*)(double*, double*, size_t, size_t, const double*, const double*, size_t);
  auto run = [&](Kernel k) {
    std::vector<double> ga = g0, gb = g0;
    k(ga.data(), gb.data(), stride, terms, buf.data(), wbuf.data(), 32);
    k(ga.data(), gb.data(), stride, terms, buf.data() + 32 * slot, wbuf.data() + 32 * slot, count - 32);
    return std::make_pair(ga, gb);
  };
  const auto base = run(detail::GramUpdateBaseline);
  std::vector<std::pair<const char*, Kernel>> kernels;
  if (__builtin_cpu_supports("avx2")) kernels.emplace_back("avx2", detail::GramUpdateAvx2);
  if (__builtin_cpu_supports("avx512f")) kernels.emplace_back("avx512f", detail::GramUpdateAvx512);
  for (const auto& [name, k] : kernels) {
    const auto got = run(k);
    for (size_t i = 0; i < terms; ++i) {
      for (size_t j = 0; j <= i; ++j) {
        const size_t e = i * stride + j;
        ASSERT_EQ(std::memcmp(&got.first[e], &base.first[e], sizeof(double)), 0) << name << " G_A(" << i << ", " << j << ")";
        ASSERT_EQ(std::memcmp(&got.second[e], &base.second[e], sizeof(double)), 0) << name << " G_B(" << i << ", " << j << ")";
      }
    }
  }
  // The baseline kernel added the radii: the lower triangle moved from its start.
  size_t moved = 0;
  for (size_t i = 0; i < terms; ++i) {
    for (size_t j = 0; j <= i; ++j) moved += base.first[i * stride + j] != g0[i * stride + j];
  }
  EXPECT_EQ(moved, terms * (terms + 1) / 2);
  // The evaluation's kernels on that G, at the 2161 angles.
  const PhaseGrid grid = StandardPhaseGrid();
  const AngularTables tables(grid, static_cast<int>(terms));
  using Eval = void (*)(const double*, const double*, size_t, size_t, const double*, size_t, size_t, size_t, double*);
  auto eval = [&](Eval e) {
    std::vector<double> out(grid.size());
    e(base.first.data(), base.second.data(), stride, terms, tables.Tile(0), tables.tiles(), terms * AngularTables::kRow,
      tables.half(), out.data());
    return out;
  };
  const std::vector<double> eb = eval(detail::GramEvaluateBaseline);
  std::vector<std::pair<const char*, Eval>> evals;
  if (__builtin_cpu_supports("avx2")) evals.emplace_back("avx2", detail::GramEvaluateAvx2);
  if (__builtin_cpu_supports("avx512f")) evals.emplace_back("avx512f", detail::GramEvaluateAvx512);
  for (const auto& [name, e] : evals) {
    const std::vector<double> got = eval(e);
    for (size_t j = 0; j < grid.size(); ++j) {
      ASSERT_TRUE(std::isfinite(got[j]));
      ASSERT_EQ(std::memcmp(&got[j], &eb[j], sizeof(double)), 0) << name << " angle " << j;
    }
  }
  std::printf("kernels compared with the baseline: %zu (avx2 %d, avx512f %d)\n", kernels.size(),
              __builtin_cpu_supports("avx2") ? 1 : 0, __builtin_cpu_supports("avx512f") ? 1 : 0);
}

// The direct sums (AddDirectIntensities, used for the check intensities when few spheres are
// added) equal the Gram matrices' evaluation of the same spheres to 1e-9 relative at every grid
// angle, and their kernels give the same bits; an accumulator summed from two (AddAccumulator,
// one with fewer terms) evaluates as one that took every sphere.
TEST(MieAngular, DirectSumsMatchTheGramEvaluation) {
  const PhaseGrid grid = StandardPhaseGrid();
  const AngularTables tables(grid, 300);
  MieWorkspace ws;
  MieCoefficients c;
  IntensityAccumulator all(300), small(120), large(300);
  std::vector<double> direct(grid.size(), 0.0);
  for (int r = 0; r < 12; ++r) {
    const double x = 2.0 + 20.0 * r;  // 2 .. 222
    const double w = 0.5 + 0.1 * r;
    ComputeCoefficients(x, Complex(1.33, 1e-8), c, ws);
    all.Add(c, w);
    (c.terms <= 120 ? small : large).Add(c, w);
    AddDirectIntensities(c, w, tables, direct);
  }
  std::vector<double> gram(grid.size()), summed(grid.size());
  all.Evaluate(tables, gram);
  large.AddAccumulator(small);
  large.Evaluate(tables, summed);
  for (size_t j = 0; j < grid.size(); ++j) {
    ASSERT_NEAR(direct[j], gram[j], 1e-9 * gram[j]) << "theta = " << grid.theta_rad[j] * 180 / std::numbers::pi;
    ASSERT_NEAR(summed[j], gram[j], 1e-12 * gram[j]) << j;
  }
  // The kernels: each this CPU runs against the baseline, on random coefficients of 77 terms.
  const size_t n = 77;
  std::vector<double> coef(4 * n);
  for (size_t i = 0; i < coef.size(); ++i) coef[i] = std::sin(1.7 * static_cast<double>(i) + 0.3);
  using Kernel = void (*)(const double*, size_t, const double*, size_t, size_t, double*, double*);
  auto run = [&](Kernel k) {
    std::vector<double> plus(tables.tiles() * AngularTables::kTile), minus(plus.size());
    k(coef.data(), n, tables.Tile(0), tables.tiles(), 300 * AngularTables::kRow, plus.data(), minus.data());
    plus.insert(plus.end(), minus.begin(), minus.end());
    return plus;
  };
  const std::vector<double> base = run(detail::DirectSumsBaseline);
  std::vector<std::pair<const char*, Kernel>> kernels;
  if (__builtin_cpu_supports("avx2")) kernels.emplace_back("avx2", detail::DirectSumsAvx2);
  if (__builtin_cpu_supports("avx512f")) kernels.emplace_back("avx512f", detail::DirectSumsAvx512);
  for (const auto& [name, k] : kernels) {
    const std::vector<double> got = run(k);
    for (size_t j = 0; j < base.size(); ++j) {
      ASSERT_EQ(std::memcmp(&got[j], &base[j], sizeof(double)), 0) << name << " lane " << j;
    }
  }
}

}  // namespace
}  // namespace skybake::mie
