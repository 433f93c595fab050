#include "optics/mie_angular.h"

#include <algorithm>

#include "io/error.h"

namespace skybake::mie {

AngularTables::AngularTables(const PhaseGrid& grid, int max_terms)
    : max_terms_(max_terms), half_(grid.half), tiles_((grid.half + kTile - 1) / kTile) {
  SKYBAKE_CHECK_GE(max_terms, 1);
  data_.assign(tiles_ * static_cast<size_t>(max_terms_) * kRow, 0.0);
  // pi_n, tau_n by the recurrences of BH eq. 4.47 (mie_sphere.h), one angle at a time.
  for (size_t j = 0; j < half_; ++j) {
    const double u = grid.mu[j];
    double* base = data_.data() + (j / kTile) * static_cast<size_t>(max_terms_) * kRow + (j % kTile);
    double pi_prev = 0.0, pi_n = 1.0;
    for (int n = 1; n <= max_terms_; ++n) {
      const double tau_n = n * u * pi_n - (n + 1.0) * pi_prev;
      const double p = pi_n + tau_n, q = pi_n - tau_n;
      const double sign = (n % 2 == 1) ? 1.0 : -1.0;  // (-1)^{n+1}
      double* row = base + static_cast<size_t>(n - 1) * kRow;
      row[0] = p;                 // p_n      (with G_A at +mu)
      row[kTile] = sign * q;      // q~_n     (with G_A at -mu)
      row[2 * kTile] = q;         // q_n      (with G_B at +mu)
      row[3 * kTile] = sign * p;  // p~_n     (with G_B at -mu)
      const double pi_next = ((2.0 * n + 1.0) * u * pi_n - (n + 1.0) * pi_prev) / n;
      pi_prev = pi_n;
      pi_n = pi_next;
    }
  }
}

namespace detail {

// Eight doubles as one value (GCC vector extension): explicit lanes, so every lane does the same
// operations in the same order whatever the instruction set: the AVX-512 kernels' lanes.
// (Always inlined into each kernel; GCC's -Wpsabi note about passing such values between
// functions compiled for different targets therefore does not apply.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double V8 __attribute__((vector_size(64)));

#if defined(__clang__)
// clang (the sanitizer and fuzz build, docs/developing.md) refuses a wide vector returned by a
// function inside a narrower target even when it is always inlined ("changes the ABI"): there the
// helpers are expressions. The lanes and their operations are the same.
typedef double V8Unaligned __attribute__((vector_size(64), aligned(8)));
#define Load8(p) (*reinterpret_cast<const V8Unaligned*>(p))
#define Splat8(x) (V8{(x), (x), (x), (x), (x), (x), (x), (x)})
#else
__attribute__((always_inline)) inline V8 Load8(const double* p) {
  V8 v;
  __builtin_memcpy(&v, p, sizeof(v));
  return v;
}
__attribute__((always_inline)) inline V8 Splat8(double x) { return V8{x, x, x, x, x, x, x, x}; }
#endif

// G += sum over the batch of w (x x^T + y y^T) for (x, y) = (Re, Im) of alpha (into ga) and of
// beta (into gb), lower triangle, rows < terms. buf holds, per batch slot r, the arrays
// [ar, ai, br, bi] of `stride` values (zero beyond the radius' terms) and wbuf the same times the
// radius' weight. The lower triangle is cut into tiles of 4 rows x 16 columns (column blocks
// from 0, rows from the block's first column on); a tile of both matrices stays in registers
// while every radius of the batch is added, so G is loaded and stored once per batch, and each
// radius costs two column loads and one broadcast per row of the tile and matrix. Per element
// the sum is G + (w_re x_re + w_im x_im), radius after radius in the order given - the order of
// a plain per-radius loop, so the batch size changes no bit. The columns of a tile past the
// diagonal, and the rows of a last tile past `terms` (zero in both buffers), are padding: never
// read back. stride is a multiple of 16 (whole tiles fit in a row and in the rows allocated).
// This tile takes 16 registers of 8 doubles for the two matrices and 8 for the radius' columns:
// it is the AVX-512 kernel (32 registers). GramUpdate chooses the kernel.
__attribute__((target("avx512f"))) void GramUpdateAvx512(double* ga, double* gb, size_t stride, size_t terms,
                                                         const double* buf, const double* wbuf, size_t count) {
  // (Four rows written out: GCC keeps named vectors in registers, arrays of them on the stack.
  // A scalar times a vector broadcasts the scalar, as Splat8 does.)
  const size_t slot = 4 * stride;
  for (size_t c = 0; c < terms; c += 16) {
    for (size_t row = c; row < terms; row += 4) {
      double* ra = ga + row * stride + c;
      double* rb = gb + row * stride + c;
#define SKYBAKE_TILE_LOAD(i)                                                       \
  V8 a##i##0 = Load8(ra + (i) * stride), a##i##1 = Load8(ra + (i) * stride + 8); \
  V8 b##i##0 = Load8(rb + (i) * stride), b##i##1 = Load8(rb + (i) * stride + 8);
      SKYBAKE_TILE_LOAD(0)
      SKYBAKE_TILE_LOAD(1)
      SKYBAKE_TILE_LOAD(2)
      SKYBAKE_TILE_LOAD(3)
#undef SKYBAKE_TILE_LOAD
      for (size_t r = 0; r < count; ++r) {
        const double* x = buf + r * slot + c;
        const double* w = wbuf + r * slot + row;
        const V8 ar0 = Load8(x), ar1 = Load8(x + 8);
        const V8 ai0 = Load8(x + stride), ai1 = Load8(x + stride + 8);
        const V8 br0 = Load8(x + 2 * stride), br1 = Load8(x + 2 * stride + 8);
        const V8 bi0 = Load8(x + 3 * stride), bi1 = Load8(x + 3 * stride + 8);
#define SKYBAKE_TILE_ROW(i)                                                \
  {                                                                        \
    const double war = w[i], wai = w[stride + (i)];                        \
    a##i##0 += war * ar0 + wai * ai0;                                      \
    a##i##1 += war * ar1 + wai * ai1;                                      \
    const double wbr = w[2 * stride + (i)], wbi = w[3 * stride + (i)];     \
    b##i##0 += wbr * br0 + wbi * bi0;                                      \
    b##i##1 += wbr * br1 + wbi * bi1;                                      \
  }
        SKYBAKE_TILE_ROW(0)
        SKYBAKE_TILE_ROW(1)
        SKYBAKE_TILE_ROW(2)
        SKYBAKE_TILE_ROW(3)
#undef SKYBAKE_TILE_ROW
      }
#define SKYBAKE_TILE_STORE(i)                                    \
  __builtin_memcpy(ra + (i) * stride, &a##i##0, sizeof(V8));     \
  __builtin_memcpy(ra + (i) * stride + 8, &a##i##1, sizeof(V8)); \
  __builtin_memcpy(rb + (i) * stride, &b##i##0, sizeof(V8));     \
  __builtin_memcpy(rb + (i) * stride + 8, &b##i##1, sizeof(V8));
      SKYBAKE_TILE_STORE(0)
      SKYBAKE_TILE_STORE(1)
      SKYBAKE_TILE_STORE(2)
      SKYBAKE_TILE_STORE(3)
#undef SKYBAKE_TILE_STORE
    }
  }
}


// Four doubles as one value: the AVX2 kernel's lanes (one AVX2 register, two SSE2 registers).
typedef double V4 __attribute__((vector_size(32)));
#if defined(__clang__)
typedef double V4Unaligned __attribute__((vector_size(32), aligned(8)));
#define Load4(p) (*reinterpret_cast<const V4Unaligned*>(p))
#else
__attribute__((always_inline)) inline V4 Load4(const double* p) {
  V4 v;
  __builtin_memcpy(&v, p, sizeof(v));
  return v;
}
#endif

// GramUpdateAvx512's sums in tiles of 4 rows x 4 columns: the two matrices' tiles take 8
// registers of 4 doubles and the radius' columns 4, within AVX2's 16 (the 4 x 16 tile there
// needs 48 and spends its time spilling them: the water cloud's table takes 5x as long with it on
// an AVX2 machine, docs/mie.md). Every element gets the same operations in the same order as in the 4 x 16 tile
// (G + (w_re x_re + w_im x_im), radius after radius; no fused multiply-add): the same bits on any
// CPU (tests/optics/mie_angular_test.cpp). Columns past the diagonal and rows past `terms` are
// padding, as there.
__attribute__((always_inline)) inline void GramUpdateTiles4(double* ga, double* gb, size_t stride, size_t terms,
                                                            const double* buf, const double* wbuf, size_t count) {
  const size_t slot = 4 * stride;
  for (size_t c = 0; c < terms; c += 4) {
    for (size_t row = c; row < terms; row += 4) {
      double* ra = ga + row * stride + c;
      double* rb = gb + row * stride + c;
#define SKYBAKE_TILE_LOAD(i)         \
  V4 a##i = Load4(ra + (i) * stride); \
  V4 b##i = Load4(rb + (i) * stride);
      SKYBAKE_TILE_LOAD(0)
      SKYBAKE_TILE_LOAD(1)
      SKYBAKE_TILE_LOAD(2)
      SKYBAKE_TILE_LOAD(3)
#undef SKYBAKE_TILE_LOAD
      for (size_t r = 0; r < count; ++r) {
        const double* x = buf + r * slot + c;
        const double* w = wbuf + r * slot + row;
        const V4 ar = Load4(x), ai = Load4(x + stride), br = Load4(x + 2 * stride), bi = Load4(x + 3 * stride);
#define SKYBAKE_TILE_ROW(i)                                            \
  {                                                                    \
    a##i += w[i] * ar + w[stride + (i)] * ai;                          \
    b##i += w[2 * stride + (i)] * br + w[3 * stride + (i)] * bi;       \
  }
        SKYBAKE_TILE_ROW(0)
        SKYBAKE_TILE_ROW(1)
        SKYBAKE_TILE_ROW(2)
        SKYBAKE_TILE_ROW(3)
#undef SKYBAKE_TILE_ROW
      }
#define SKYBAKE_TILE_STORE(i)                               \
  __builtin_memcpy(ra + (i) * stride, &a##i, sizeof(V4)); \
  __builtin_memcpy(rb + (i) * stride, &b##i, sizeof(V4));
      SKYBAKE_TILE_STORE(0)
      SKYBAKE_TILE_STORE(1)
      SKYBAKE_TILE_STORE(2)
      SKYBAKE_TILE_STORE(3)
#undef SKYBAKE_TILE_STORE
    }
  }
}
__attribute__((target("avx2"))) void GramUpdateAvx2(double* ga, double* gb, size_t stride, size_t terms, const double* buf,
                                                    const double* wbuf, size_t count) {
  GramUpdateTiles4(ga, gb, stride, terms, buf, wbuf, count);
}
void GramUpdateBaseline(double* ga, double* gb, size_t stride, size_t terms, const double* buf, const double* wbuf,
                        size_t count) {
  GramUpdateTiles4(ga, gb, stride, terms, buf, wbuf, count);
}

// The direct sums: per angle of the tiles, plus = |U(+mu)|^2 + |V(+mu)|^2 and minus = |U(-mu)|^2
// + |V(-mu)|^2 with U(+mu) = sum alpha p, U(-mu) = sum alpha q~, V(+mu) = sum beta q, V(-mu) =
// sum beta p~ (coef: Re alpha, Im alpha, Re beta, Im beta per term). One tile of 8 angles per pass
// over the terms in 8 lanes (AVX-512), half a tile in 4 lanes (AVX2, baseline): a lane's
// operations are the same in both.
__attribute__((target("avx512f"))) void DirectSumsAvx512(const double* coef, size_t n, const double* tables,
                                                         size_t tiles, size_t tile_stride, double* plus, double* minus) {
  constexpr size_t T = AngularTables::kTile;
  constexpr size_t R = AngularTables::kRow;
  for (size_t k = 0; k < tiles; ++k) {
    V8 u0 = Splat8(0.0), u1 = u0, um0 = u0, um1 = u0, v0 = u0, v1 = u0, vm0 = u0, vm1 = u0;
    const double* tile = tables + k * tile_stride;
    for (size_t j = 0; j < n; ++j) {
      const double* t = tile + j * R;
      const double ar = coef[4 * j], ai = coef[4 * j + 1], br = coef[4 * j + 2], bi = coef[4 * j + 3];
      const V8 p = Load8(t), qt = Load8(t + T), q = Load8(t + 2 * T), pt = Load8(t + 3 * T);
      u0 += ar * p;
      u1 += ai * p;
      um0 += ar * qt;
      um1 += ai * qt;
      v0 += br * q;
      v1 += bi * q;
      vm0 += br * pt;
      vm1 += bi * pt;
    }
    const V8 pl = ((u0 * u0 + u1 * u1) + v0 * v0) + v1 * v1;
    const V8 mi = ((um0 * um0 + um1 * um1) + vm0 * vm0) + vm1 * vm1;
    __builtin_memcpy(plus + k * T, &pl, sizeof(pl));
    __builtin_memcpy(minus + k * T, &mi, sizeof(mi));
  }
}

__attribute__((always_inline)) inline void DirectSumsLanes4(const double* coef, size_t n, const double* tables,
                                                            size_t tiles, size_t tile_stride, double* plus,
                                                            double* minus) {
  constexpr size_t T = AngularTables::kTile;
  constexpr size_t R = AngularTables::kRow;
  const V4 zero = {0.0, 0.0, 0.0, 0.0};
  for (size_t k = 0; k < tiles; ++k) {
    for (size_t h = 0; h < T; h += 4) {
      V4 u0 = zero, u1 = zero, um0 = zero, um1 = zero, v0 = zero, v1 = zero, vm0 = zero, vm1 = zero;
      const double* tile = tables + k * tile_stride + h;
      for (size_t j = 0; j < n; ++j) {
        const double* t = tile + j * R;
        const double ar = coef[4 * j], ai = coef[4 * j + 1], br = coef[4 * j + 2], bi = coef[4 * j + 3];
        const V4 p = Load4(t), qt = Load4(t + T), q = Load4(t + 2 * T), pt = Load4(t + 3 * T);
        u0 += ar * p;
        u1 += ai * p;
        um0 += ar * qt;
        um1 += ai * qt;
        v0 += br * q;
        v1 += bi * q;
        vm0 += br * pt;
        vm1 += bi * pt;
      }
      const V4 pl = ((u0 * u0 + u1 * u1) + v0 * v0) + v1 * v1;
      const V4 mi = ((um0 * um0 + um1 * um1) + vm0 * vm0) + vm1 * vm1;
      __builtin_memcpy(plus + k * T + h, &pl, sizeof(pl));
      __builtin_memcpy(minus + k * T + h, &mi, sizeof(mi));
    }
  }
}
__attribute__((target("avx2"))) void DirectSumsAvx2(const double* coef, size_t n, const double* tables, size_t tiles,
                                                    size_t tile_stride, double* plus, double* minus) {
  DirectSumsLanes4(coef, n, tables, tiles, tile_stride, plus, minus);
}
void DirectSumsBaseline(const double* coef, size_t n, const double* tables, size_t tiles, size_t tile_stride,
                        double* plus, double* minus) {
  DirectSumsLanes4(coef, n, tables, tiles, tile_stride, plus, minus);
}

// The kernels' instruction set on this CPU, read once: 2 AVX-512, 1 AVX2, 0 baseline x86-64.
int KernelLevel() {
  static const int level = __builtin_cpu_supports("avx512f") ? 2 : __builtin_cpu_supports("avx2") ? 1 : 0;
  return level;
}

void GramUpdate(double* ga, double* gb, size_t stride, size_t terms, const double* buf, const double* wbuf, size_t count) {
  const int isa = KernelLevel();
  if (isa == 2) GramUpdateAvx512(ga, gb, stride, terms, buf, wbuf, count);
  else if (isa == 1) GramUpdateAvx2(ga, gb, stride, terms, buf, wbuf, count);
  else GramUpdateBaseline(ga, gb, stride, terms, buf, wbuf, count);
}

// out[j] = (p^T G_A p + q^T G_B q)/4 at +mu_j and (q~^T G_A q~ + p~^T G_B p~)/4 at -mu_j, using
// x^T G x = sum_n x_n (G_nn x_n + 2 sum_{n' < n} G_nn' x_n'). Per row n the inner sum runs in two
// partial sums (n' even, n' odd; an odd row's last column n - 1 goes to the even one), and the
// rows are visited in pairs (n, n + 1), n even, which share the loads of the tables' columns.
// NT tiles of angles share each pass over G (one broadcast of G_nn' serves NT tiles). Every
// lane's operations are those of the plain row-by-row loop with those two partial sums, in the
// 8-lane and the 4-lane forms alike.
//
// One matrix's part of NT tiles, from the tables' columns at `part` ((p, q~) with G_A, (q, p~)
// with G_B): acc_x at +mu, acc_y at -mu. Not inlined, so that the other matrix's sums wait in
// memory: two tiles' 16 partial sums, 4 accumulators, 4 table columns and 4 broadcasts of G fit
// the 32 registers (a partial sum spilled to the stack makes every pass over a column pair wait
// on its store and reload). G's elements multiply the columns as scalars, which GCC broadcasts
// straight from memory (a Splat8 of a loaded value goes through the stack, four narrow stores
// read back as one wide load). With both round trips the evaluation took 1.9x as long (perf, 10
// of the water cloud's wavelengths).
template <size_t NT>
__attribute__((target("avx512f"), noinline)) void EvaluatePart(const double* g, size_t stride, size_t terms,
                                                                const double* tiles0, size_t tile_stride, size_t part,
                                                                V8* acc_x, V8* acc_y) {
  constexpr size_t T = AngularTables::kTile;
  constexpr size_t R = AngularTables::kRow;
  for (size_t t = 0; t < NT; ++t) acc_x[t] = acc_y[t] = Splat8(0.0);
  size_t row = 0;
  for (; row + 2 <= terms; row += 2) {
    const double* g0 = g + row * stride;  // rows n = row (even) and n + 1
    const double* g1 = g0 + stride;
    V8 ax0[NT], ax1[NT], ay0[NT], ay1[NT], bx0[NT], bx1[NT], by0[NT], by1[NT];
    for (size_t t = 0; t < NT; ++t) {
      ax0[t] = ax1[t] = ay0[t] = ay1[t] = bx0[t] = bx1[t] = by0[t] = by1[t] = Splat8(0.0);
    }
    for (size_t c = 0; c < row; c += 2) {
      const double a0 = g0[c], a1 = g0[c + 1], b0 = g1[c], b1 = g1[c + 1];
      for (size_t t = 0; t < NT; ++t) {
        const double* tt = tiles0 + t * tile_stride + part + c * R;
        const V8 x0 = Load8(tt), y0 = Load8(tt + T), x1 = Load8(tt + R), y1 = Load8(tt + R + T);
        ax0[t] += a0 * x0;
        ay0[t] += a0 * y0;
        ax1[t] += a1 * x1;
        ay1[t] += a1 * y1;
        bx0[t] += b0 * x0;
        by0[t] += b0 * y0;
        bx1[t] += b1 * x1;
        by1[t] += b1 * y1;
      }
    }
    const double bl = g1[row], d0 = g0[row], d1 = g1[row + 1];
    for (size_t t = 0; t < NT; ++t) {
      const double* tt = tiles0 + t * tile_stride + part + row * R;
      const V8 x0 = Load8(tt), y0 = Load8(tt + T), x1 = Load8(tt + R), y1 = Load8(tt + R + T);
      bx0[t] += bl * x0;  // row n + 1's last column, n
      by0[t] += bl * y0;
      acc_x[t] += x0 * (d0 * x0 + 2.0 * (ax0[t] + ax1[t]));
      acc_y[t] += y0 * (d0 * y0 + 2.0 * (ay0[t] + ay1[t]));
      acc_x[t] += x1 * (d1 * x1 + 2.0 * (bx0[t] + bx1[t]));
      acc_y[t] += y1 * (d1 * y1 + 2.0 * (by0[t] + by1[t]));
    }
  }
  if (row < terms) {  // the last row alone (even: its columns pair up)
    const double* g0 = g + row * stride;
    V8 ax0[NT], ax1[NT], ay0[NT], ay1[NT];
    for (size_t t = 0; t < NT; ++t) ax0[t] = ax1[t] = ay0[t] = ay1[t] = Splat8(0.0);
    for (size_t c = 0; c < row; c += 2) {
      const double a0 = g0[c], a1 = g0[c + 1];
      for (size_t t = 0; t < NT; ++t) {
        const double* tt = tiles0 + t * tile_stride + part + c * R;
        ax0[t] += a0 * Load8(tt);
        ay0[t] += a0 * Load8(tt + T);
        ax1[t] += a1 * Load8(tt + R);
        ay1[t] += a1 * Load8(tt + R + T);
      }
    }
    const double d0 = g0[row];
    for (size_t t = 0; t < NT; ++t) {
      const double* tt = tiles0 + t * tile_stride + part + row * R;
      const V8 x0 = Load8(tt), y0 = Load8(tt + T);
      acc_x[t] += x0 * (d0 * x0 + 2.0 * (ax0[t] + ax1[t]));
      acc_y[t] += y0 * (d0 * y0 + 2.0 * (ay0[t] + ay1[t]));
    }
  }
}

// Both matrices' parts of NT tiles: plus at +mu, minus at -mu (0 + G_A's part + G_B's).
template <size_t NT>
__attribute__((always_inline)) inline void EvaluateTiles(const double* ga, const double* gb, size_t stride,
                                                         size_t terms, const double* tiles0, size_t tile_stride,
                                                         V8* plus, V8* minus) {
  constexpr size_t T = AngularTables::kTile;
  V8 ax[NT], ay[NT], bx[NT], by[NT];
  EvaluatePart<NT>(ga, stride, terms, tiles0, tile_stride, 0, ax, ay);
  EvaluatePart<NT>(gb, stride, terms, tiles0, tile_stride, 2 * T, bx, by);
  for (size_t t = 0; t < NT; ++t) {
    plus[t] = minus[t] = Splat8(0.0);
    plus[t] += ax[t];
    minus[t] += ay[t];
    plus[t] += bx[t];
    minus[t] += by[t];
  }
}

// Two tiles of 8 angles per pass over G take 20 registers of 8 doubles for the partial sums: the
// AVX-512 kernel. GramEvaluate chooses the kernel.
__attribute__((target("avx512f"))) void GramEvaluateAvx512(const double* ga, const double* gb, size_t stride, size_t terms,
                                                           const double* tables, size_t tiles, size_t tile_stride,
                                                           size_t half, double* out) {
  constexpr size_t T = AngularTables::kTile;
  constexpr size_t kPair = 2;
  const size_t n_out = 2 * half - 1;
  for (size_t k = 0; k < tiles; k += kPair) {
    V8 plus[kPair], minus[kPair];
    const size_t nt = std::min(kPair, tiles - k);
    if (nt == kPair) {
      EvaluateTiles<kPair>(ga, gb, stride, terms, tables + k * tile_stride, tile_stride, plus, minus);
    } else {
      EvaluateTiles<1>(ga, gb, stride, terms, tables + k * tile_stride, tile_stride, plus, minus);
    }
    for (size_t t = 0; t < nt; ++t) {
      for (size_t l = 0; l < T; ++l) {
        const size_t j = (k + t) * T + l;
        if (j >= half) break;
        out[j] = 0.25 * plus[t][l];
        if (j + 1 < half) out[n_out - 1 - j] = 0.25 * minus[t][l];
      }
    }
  }
}

// EvaluateTiles<1> on lanes h .. h + 3 of one tile: 10 registers of 4 doubles for the partial
// sums, within AVX2's 16 (the 8-lane form needs 40 there). A lane's operations are those of the
// 8-lane form: the same bits.
__attribute__((always_inline)) inline void EvaluateQuarterLanes(const double* ga, const double* gb, size_t stride, size_t terms,
                                                                const double* tile, size_t h, V4* plus, V4* minus) {
  constexpr size_t T = AngularTables::kTile;
  constexpr size_t R = AngularTables::kRow;
  const V4 zero = {0.0, 0.0, 0.0, 0.0};
  *plus = *minus = zero;
  for (int which = 0; which < 2; ++which) {
    const double* g = which == 0 ? ga : gb;
    const double* tp = tile + (which == 0 ? 0 : 2 * T) + h;
    V4 acc_x = zero, acc_y = zero;
    size_t row = 0;
    for (; row + 2 <= terms; row += 2) {
      const double* g0 = g + row * stride;
      const double* g1 = g0 + stride;
      V4 ax0 = zero, ax1 = zero, ay0 = zero, ay1 = zero, bx0 = zero, bx1 = zero, by0 = zero, by1 = zero;
      for (size_t c = 0; c < row; c += 2) {
        const double* tt = tp + c * R;
        const double a0 = g0[c], a1 = g0[c + 1], b0 = g1[c], b1 = g1[c + 1];
        const V4 x0 = Load4(tt), y0 = Load4(tt + T), x1 = Load4(tt + R), y1 = Load4(tt + R + T);
        ax0 += a0 * x0;
        ay0 += a0 * y0;
        ax1 += a1 * x1;
        ay1 += a1 * y1;
        bx0 += b0 * x0;
        by0 += b0 * y0;
        bx1 += b1 * x1;
        by1 += b1 * y1;
      }
      const double bl = g1[row], d0 = g0[row], d1 = g1[row + 1];
      const double* tt = tp + row * R;
      const V4 x0 = Load4(tt), y0 = Load4(tt + T), x1 = Load4(tt + R), y1 = Load4(tt + R + T);
      bx0 += bl * x0;
      by0 += bl * y0;
      acc_x += x0 * (d0 * x0 + 2.0 * (ax0 + ax1));
      acc_y += y0 * (d0 * y0 + 2.0 * (ay0 + ay1));
      acc_x += x1 * (d1 * x1 + 2.0 * (bx0 + bx1));
      acc_y += y1 * (d1 * y1 + 2.0 * (by0 + by1));
    }
    if (row < terms) {
      const double* g0 = g + row * stride;
      V4 ax0 = zero, ax1 = zero, ay0 = zero, ay1 = zero;
      for (size_t c = 0; c < row; c += 2) {
        const double* tt = tp + c * R;
        const double a0 = g0[c], a1 = g0[c + 1];
        ax0 += a0 * Load4(tt);
        ay0 += a0 * Load4(tt + T);
        ax1 += a1 * Load4(tt + R);
        ay1 += a1 * Load4(tt + R + T);
      }
      const double d0 = g0[row];
      const double* tt = tp + row * R;
      const V4 x0 = Load4(tt), y0 = Load4(tt + T);
      acc_x += x0 * (d0 * x0 + 2.0 * (ax0 + ax1));
      acc_y += y0 * (d0 * y0 + 2.0 * (ay0 + ay1));
    }
    *plus += acc_x;
    *minus += acc_y;
  }
}

__attribute__((always_inline)) inline void GramEvaluateLanes4(const double* ga, const double* gb, size_t stride, size_t terms,
                                                              const double* tables, size_t tiles, size_t tile_stride,
                                                              size_t half, double* out) {
  constexpr size_t T = AngularTables::kTile;
  const size_t n_out = 2 * half - 1;
  for (size_t k = 0; k < tiles; ++k) {
    for (size_t h = 0; h < T; h += 4) {
      if (k * T + h >= half) break;
      V4 plus, minus;
      EvaluateQuarterLanes(ga, gb, stride, terms, tables + k * tile_stride, h, &plus, &minus);
      for (size_t l = 0; l < 4; ++l) {
        const size_t j = k * T + h + l;
        if (j >= half) break;
        out[j] = 0.25 * plus[l];
        if (j + 1 < half) out[n_out - 1 - j] = 0.25 * minus[l];
      }
    }
  }
}
__attribute__((target("avx2"))) void GramEvaluateAvx2(const double* ga, const double* gb, size_t stride, size_t terms,
                                                      const double* tables, size_t tiles, size_t tile_stride, size_t half,
                                                      double* out) {
  GramEvaluateLanes4(ga, gb, stride, terms, tables, tiles, tile_stride, half, out);
}
void GramEvaluateBaseline(const double* ga, const double* gb, size_t stride, size_t terms, const double* tables, size_t tiles,
                          size_t tile_stride, size_t half, double* out) {
  GramEvaluateLanes4(ga, gb, stride, terms, tables, tiles, tile_stride, half, out);
}

void DirectSums(const double* coef, size_t n, const double* tables, size_t tiles, size_t tile_stride, double* plus,
                double* minus) {
  const int isa = KernelLevel();
  if (isa == 2) DirectSumsAvx512(coef, n, tables, tiles, tile_stride, plus, minus);
  else if (isa == 1) DirectSumsAvx2(coef, n, tables, tiles, tile_stride, plus, minus);
  else DirectSumsBaseline(coef, n, tables, tiles, tile_stride, plus, minus);
}

void GramEvaluate(const double* ga, const double* gb, size_t stride, size_t terms, const double* tables, size_t tiles,
                  size_t tile_stride, size_t half, double* out) {
  const int isa = KernelLevel();
  if (isa == 2) GramEvaluateAvx512(ga, gb, stride, terms, tables, tiles, tile_stride, half, out);
  else if (isa == 1) GramEvaluateAvx2(ga, gb, stride, terms, tables, tiles, tile_stride, half, out);
  else GramEvaluateBaseline(ga, gb, stride, terms, tables, tiles, tile_stride, half, out);
}
#pragma GCC diagnostic pop

}  // namespace detail

void AddDirectIntensities(const MieCoefficients& c, double weight, const AngularTables& tables, std::span<double> out) {
  constexpr size_t T = AngularTables::kTile;
  const size_t half = tables.half(), n_out = 2 * half - 1, tiles = tables.tiles();
  SKYBAKE_CHECK_EQ(out.size(), n_out);
  SKYBAKE_CHECK_LE(c.terms, tables.max_terms());
  const size_t n = static_cast<size_t>(c.terms);
  thread_local std::vector<double> coef, plus, minus;
  coef.resize(4 * n);
  for (size_t j = 0; j < n; ++j) {
    const double i = static_cast<double>(j + 1);
    const double cn = (2.0 * i + 1.0) / (i * (i + 1.0));
    const Complex alpha = cn * (c.a[j] + c.b[j]);
    const Complex beta = cn * (c.a[j] - c.b[j]);
    coef[4 * j] = alpha.real();
    coef[4 * j + 1] = alpha.imag();
    coef[4 * j + 2] = beta.real();
    coef[4 * j + 3] = beta.imag();
  }
  plus.resize(tiles * T);
  minus.resize(tiles * T);
  detail::DirectSums(coef.data(), n, tables.Tile(0), tiles, static_cast<size_t>(tables.max_terms()) * AngularTables::kRow,
                     plus.data(), minus.data());
  for (size_t j = 0; j < half; ++j) {
    out[j] += weight * 0.25 * plus[j];
    if (j + 1 < half) out[n_out - 1 - j] += weight * 0.25 * minus[j];
  }
}

IntensityAccumulator::IntensityAccumulator(int max_terms) { Reset(max_terms); }

void IntensityAccumulator::Reset(int max_terms) {
  SKYBAKE_CHECK_GE(max_terms, 1);
  n_ = max_terms;
  stride_ = (static_cast<size_t>(max_terms) + 15) / 16 * 16;
  ga_.assign(stride_ * stride_, 0.0);
  gb_.assign(stride_ * stride_, 0.0);
  buf_.assign(kBatch * 4 * stride_, 0.0);
  wbuf_.assign(kBatch * 4 * stride_, 0.0);
  slot_len_.assign(kBatch, 0);
  count_ = 0;
  batch_terms_ = 0;
  used_ = 0;
}

void IntensityAccumulator::Add(const MieCoefficients& c, double weight) {
  SKYBAKE_CHECK_LE(c.terms, n_);
  if (count_ == kBatch) Flush();
  double* b = buf_.data() + count_ * 4 * stride_;
  double* w = wbuf_.data() + count_ * 4 * stride_;
  const size_t n = static_cast<size_t>(c.terms);
  // The slot may hold a longer earlier radius: zero what this one does not overwrite, in both
  // buffers (a row of G past this radius' terms must get w x = 0, and its stale w times this
  // radius' x would not be).
  if (slot_len_[count_] > n) {
    for (size_t k = 0; k < 4; ++k) {
      std::fill(b + k * stride_ + n, b + k * stride_ + slot_len_[count_], 0.0);
      std::fill(w + k * stride_ + n, w + k * stride_ + slot_len_[count_], 0.0);
    }
  }
  slot_len_[count_] = std::max(slot_len_[count_], n);
  for (size_t j = 0; j < n; ++j) {
    const double i = static_cast<double>(j + 1);
    const double cn = (2.0 * i + 1.0) / (i * (i + 1.0));
    const Complex alpha = cn * (c.a[j] + c.b[j]);
    const Complex beta = cn * (c.a[j] - c.b[j]);
    b[j] = alpha.real();
    b[stride_ + j] = alpha.imag();
    b[2 * stride_ + j] = beta.real();
    b[3 * stride_ + j] = beta.imag();
    w[j] = weight * alpha.real();
    w[stride_ + j] = weight * alpha.imag();
    w[2 * stride_ + j] = weight * beta.real();
    w[3 * stride_ + j] = weight * beta.imag();
  }
  batch_terms_ = std::max(batch_terms_, c.terms);
  used_ = std::max(used_, c.terms);
  ++count_;
}

void IntensityAccumulator::Flush() {
  if (count_ == 0) return;
  detail::GramUpdate(ga_.data(), gb_.data(), stride_, static_cast<size_t>(batch_terms_), buf_.data(), wbuf_.data(),
                     count_);
  count_ = 0;
  batch_terms_ = 0;
}

void IntensityAccumulator::Scale(double factor) {
  Flush();
  for (double& v : ga_) v *= factor;
  for (double& v : gb_) v *= factor;
}

void IntensityAccumulator::AddAccumulator(IntensityAccumulator& other) {
  SKYBAKE_CHECK_LE(other.n_, n_);
  Flush();
  other.Flush();
  const size_t rows = static_cast<size_t>(other.used_);
  for (size_t i = 0; i < rows; ++i) {
    for (size_t j = 0; j <= i; ++j) {
      ga_[i * stride_ + j] += other.ga_[i * other.stride_ + j];
      gb_[i * stride_ + j] += other.gb_[i * other.stride_ + j];
    }
  }
  used_ = std::max(used_, other.used_);
}

void IntensityAccumulator::Evaluate(const AngularTables& tables, std::span<double> out) {
  SKYBAKE_CHECK_EQ(out.size(), 2 * tables.half() - 1);
  SKYBAKE_CHECK_LE(used_, tables.max_terms());
  Flush();
  detail::GramEvaluate(ga_.data(), gb_.data(), stride_, static_cast<size_t>(used_), tables.Tile(0),
                       tables.tiles(), static_cast<size_t>(tables.max_terms()) * AngularTables::kRow, tables.half(),
                       out.data());
}

}  // namespace skybake::mie
