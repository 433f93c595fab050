// optics/mie_angular.h: the batched Gram update adds every radius to every matrix element in
// the order given, so how the radii fall into batches changes no bit of the intensities.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
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

}  // namespace
}  // namespace skybake::mie
