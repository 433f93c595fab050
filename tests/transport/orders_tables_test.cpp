// The solve's tables (transport/orders/grid.h): ZeroTable gives n zeros whichever way the block
// is allocated - from operator new below kMapFrom bytes, zeroed in parallel, or as a fresh
// mapping from kMapFrom, which the kernel zeroes and ZeroTable does not write - also when the
// table held other values before.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>

#include "transport/orders/grid.h"

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

}  // namespace
}  // namespace skybake::orders
