// Small pieces shared by the phases of `orders`: the solve's tables, interpolation positions on
// sorted grids, and node placement uniform in a monotone parameter.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include "io/interp.h"

namespace skybake::orders {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// The solve's tables (a field over every cell and wavelength: 88 MB for high's daylight part) in
// vectors whose elements start uninitialised. Blocks of at least kMapFrom bytes are their own
// anonymous mappings made with MAP_POPULATE: the kernel hands them over zeroed and resident in
// one call, where touching fresh pages faults once per 4 KB (on a virtual machine each fault
// traps to the hypervisor: 4.5 % of the hazed LUT's CPU time, with as much again in the zeroing
// that followed) - so ZeroTable need not write them. Smaller blocks come from operator new and
// ZeroTable zeroes them in parallel blocks. The same values, the same bytes.
void* MapZeroedPages(size_t bytes);           // throws std::bad_alloc
void UnmapPages(void* p, size_t bytes);
inline constexpr size_t kMapFrom = size_t{16} << 20;
// Whether a block of `bytes` is its own zeroed mapping (the allocator's and ZeroTable's one rule).
inline constexpr bool IsMappedBlock(size_t bytes) { return bytes >= kMapFrom; }
template <class T>
struct UninitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitAllocator<U>;
  };
  UninitAllocator() = default;
  template <class U>
  UninitAllocator(const UninitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
  T* allocate(size_t n) {
    if (!IsMappedBlock(n * sizeof(T))) return std::allocator<T>::allocate(n);
    return static_cast<T*>(MapZeroedPages(n * sizeof(T)));
  }
  void deallocate(T* p, size_t n) noexcept {
    if (!IsMappedBlock(n * sizeof(T))) std::allocator<T>::deallocate(p, n);
    else UnmapPages(p, n * sizeof(T));
  }
};
using Table = std::vector<float, UninitAllocator<float>>;

// The columns ws of a table [row * nw + w] (a wavelength batch's slice: medium.h, sun_tables.h).
template <class V>
V SliceColumns(const V& v, size_t nw, const std::vector<size_t>& ws) {
  const size_t rows = v.size() / nw, nv = ws.size();
  V out(rows * nv);
  for (size_t i = 0; i < rows; ++i) {
    for (size_t j = 0; j < nv; ++j) out[i * nv + j] = v[i * nw + ws[j]];
  }
  return out;
}

// v = n zeros: a fresh mapping (zeroed by the kernel) from kMapFrom bytes, else written in
// parallel blocks.
void ZeroTable(Table* v, size_t n);

// Linear interpolation position on a sorted grid: index of the lower node and weight of the upper.
struct Lerp {
  size_t i = 0;
  double t = 0.0;
};
[[gnu::always_inline]] inline Lerp Locate(const IntervalLocator& loc, double v) {
  const std::vector<double>& x = loc.x();
  if (v <= x.front()) return {0, 0.0};
  if (v >= x.back()) return {x.size() - 2, 1.0};
  const size_t i = loc.Find(v);
  return {i, (v - x[i]) / (x[i + 1] - x[i])};
}
Lerp Locate(const std::vector<double>& x, double v);

// The altitude in [lo, hi] where a non-decreasing f reaches `target`, by bisection to 1 mm.
template <class F>
double AltitudeWhere(const F& f, double target, double lo, double hi) {
  for (int it = 0; it < 60 && hi - lo > 1e-3; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// n altitudes in [0, H] uniform in a monotone s(h) with s(0) = 0 and s(H) = 1 (bisection to 1 mm;
// the ends exactly 0 and H): the node placements that follow both altitude and optical depth.
template <class S>
std::vector<double> AltitudesUniformIn(const S& s_of, int n, double H) {
  std::vector<double> h;
  for (int i = 0; i < n; ++i) {
    const double u = static_cast<double>(i) / (n - 1);
    h.push_back(AltitudeWhere(s_of, u, i == n - 1 ? H : 0.0, i == 0 ? 0.0 : H));
  }
  return h;
}

}  // namespace skybake::orders
