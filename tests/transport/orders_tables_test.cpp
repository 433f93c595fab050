// The solve's tables (transport/orders/grid.h, the batch size of solve.h): ZeroTable gives n zeros whichever way the block
// is allocated - from operator new below kMapFrom bytes, zeroed in parallel, or as a fresh
// mapping from kMapFrom, which the kernel zeroes and ZeroTable does not write - also when the
// table held other values before.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>

#include "transport/orders/grid.h"
#include "transport/orders/solve.h"

namespace skybake::orders {
namespace {

bool AllZero(const Table& t) {
  return std::all_of(t.begin(), t.end(), [](float v) { return v == 0.0f; });
}

TEST(OrdersTables, ZeroTableGivesZerosBelowAndAboveTheMappingSize) {
  const size_t mapped = kMapFrom / sizeof(float);  // the smallest table that is its own mapping
  for (size_t n : {size_t{1}, size_t{1000}, mapped - 1, mapped, mapped + 12345}) {
    Table t;
    ZeroTable(&t, n);
    ASSERT_EQ(t.size(), n);
    EXPECT_TRUE(AllZero(t)) << n << " floats, fresh";
    std::fill(t.begin(), t.end(), 7.0f);
    ZeroTable(&t, n);  // the same size again: a new block, not the old values
    ASSERT_EQ(t.size(), n);
    EXPECT_TRUE(AllZero(t)) << n << " floats, after holding 7s";
  }
}

TEST(OrdersTables, MappedTablesCopyAndSwapLikeVectors) {
  const size_t n = kMapFrom / sizeof(float) + 3;
  Table a, b;
  ZeroTable(&a, n);
  ZeroTable(&b, 10);
  a[n - 1] = 1.5f;
  b[9] = 2.5f;
  std::swap(a, b);  // as the solve swaps L and L_next
  ASSERT_EQ(a.size(), 10u);
  ASSERT_EQ(b.size(), n);
  EXPECT_EQ(a[9], 2.5f);
  EXPECT_EQ(b[n - 1], 1.5f);
  const Table c = b;  // a copy is a mapping of its own
  EXPECT_EQ(c[n - 1], 1.5f);
  EXPECT_EQ(c[0], 0.0f);
  b.clear();
  b.shrink_to_fit();
  EXPECT_EQ(c[n - 1], 1.5f);
}

// The wavelengths per batch (solve.h): all where they fit; a multiple of 8 where 8 fit; the
// fewest batches shared evenly, so that no last batch holds one wavelength and the reference
// (25 of which 24 fit: 16 and 9 with the reference, not 24 and 1).
TEST(OrdersTables, BatchSizeSharesTheWavelengthsEvenly) {
  EXPECT_EQ(BatchSize(25, 25), 25u);
  EXPECT_EQ(BatchSize(25, 1000), 25u);
  EXPECT_EQ(BatchSize(25, 24), 16u);
  EXPECT_EQ(BatchSize(25, 17), 16u);
  EXPECT_EQ(BatchSize(41, 40), 24u);  // 24 and 17 with the reference
  EXPECT_EQ(BatchSize(21, 8), 8u);    // 8, 8 and 7, each with the reference
  EXPECT_EQ(BatchSize(21, 16), 16u);  // 16 and 5 + 1
  EXPECT_EQ(BatchSize(21, 1), 2u);    // one wavelength and the reference
  EXPECT_EQ(BatchSize(21, 0), 2u);
  EXPECT_EQ(BatchSize(21, 6), 6u);    // 5 + 1, 6, 5 + 1, 5 + 1
  EXPECT_EQ(BatchSize(2, 0), 2u);
  EXPECT_EQ(BatchSize(1, 0), 1u);
  EXPECT_EQ(BatchSize(95, 70), 48u);  // 48 and 47 + 1, not 64 and 31 + 1
}

}  // namespace
}  // namespace skybake::orders
