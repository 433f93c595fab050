#include "transport/orders/grid.h"

#include <sys/mman.h>

#include <new>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace skybake::orders {

void* MapZeroedPages(size_t bytes) {
  void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_POPULATE, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  return p;
}

void UnmapPages(void* p, size_t bytes) { munmap(p, bytes); }

void ZeroTable(Table* v, size_t n) {
  Table().swap(*v);
  v->resize(n);  // a capacity of at least n: a fresh mapping whenever n floats reach kMapFrom
  if (IsMappedBlock(n * sizeof(float))) return;
  constexpr size_t kBlock = size_t{1} << 18;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, (n + kBlock - 1) / kBlock, 1), [&](const tbb::blocked_range<size_t>& rg) {
    for (size_t b = rg.begin(); b != rg.end(); ++b) std::fill(v->begin() + b * kBlock, v->begin() + std::min(n, (b + 1) * kBlock), 0.0f);
  });
}

Lerp Locate(const std::vector<double>& x, double v) {
  if (v <= x.front()) return {0, 0.0};
  if (v >= x.back()) return {x.size() - 2, 1.0};
  size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), v) - x.begin()) - 1;
  return {i, (v - x[i]) / (x[i + 1] - x[i])};
}

}  // namespace skybake::orders
