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
// operations in the same order whatever the instruction set (one AVX-512 register, two AVX2
// registers or four SSE2 registers).
// (Always inlined into each clone; GCC's -Wpsabi note about passing such values between
// functions compiled for different targets therefore does not apply.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double V8 __attribute__((vector_size(64)));

#if defined(__clang__)
// clang (the sanitizer and fuzz build, docs/developing.md) refuses a 64-byte vector returned by a
// function inside the avx2 clone even when it is always inlined ("changes the ABI"): there the
// two helpers are expressions. The lanes and their operations are the same.
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
// [ar, ai, br, bi] of `stride` values (zero beyond the radius' terms) and w_i = the weighted
// values at each row. Rows are processed in blocks of 8 columns held in registers across the
// batch (the columns past the diagonal, up to the block's end, are padding: never read back).
__attribute__((target_clones("avx512f", "avx2", "default")))
void GramUpdate(double* ga, double* gb, size_t stride, size_t terms, const double* buf, const double* wbuf,
                size_t count) {
  constexpr size_t kMax = 8;
  for (size_t row = 0; row < terms; ++row) {
    double* ra = ga + row * stride;
    double* rb = gb + row * stride;
    V8 war[kMax], wai[kMax], wbr[kMax], wbi[kMax];
    for (size_t r = 0; r < count; ++r) {
      const double* w = wbuf + r * 4 * stride;
      war[r] = Splat8(w[row]);
      wai[r] = Splat8(w[stride + row]);
      wbr[r] = Splat8(w[2 * stride + row]);
      wbi[r] = Splat8(w[3 * stride + row]);
    }
    for (size_t c = 0; c <= row; c += 8) {
      V8 va = Load8(ra + c), vb = Load8(rb + c);
      for (size_t r = 0; r < count; ++r) {
        const double* b = buf + r * 4 * stride + c;
        va += war[r] * Load8(b) + wai[r] * Load8(b + stride);
        vb += wbr[r] * Load8(b + 2 * stride) + wbi[r] * Load8(b + 3 * stride);
      }
      __builtin_memcpy(ra + c, &va, sizeof(va));
      __builtin_memcpy(rb + c, &vb, sizeof(vb));
    }
  }
}

// out[j] = (p^T G_A p + q^T G_B q)/4 at +mu_j and (q~^T G_A q~ + p~^T G_B p~)/4 at -mu_j, using
// x^T G x = sum_n x_n (G_nn x_n + 2 sum_{n' < n} G_nn' x_n'); the inner sums run in four
// interleaved partial sums (n' mod 4) to hide the addition latency.
__attribute__((target_clones("avx512f", "avx2", "default")))
void GramEvaluate(const double* ga, const double* gb, size_t stride, size_t terms, const double* tables,
                  size_t tiles, size_t tile_stride, size_t half, double* out) {
  constexpr size_t T = AngularTables::kTile;
  constexpr size_t R = AngularTables::kRow;
  const size_t n_out = 2 * half - 1;
  for (size_t k = 0; k < tiles; ++k) {
    const double* tile = tables + k * tile_stride;
    V8 plus = Splat8(0.0), minus = Splat8(0.0);
    for (int which = 0; which < 2; ++which) {
      const double* g = which == 0 ? ga : gb;
      const double* tx = tile + (which == 0 ? 0 : 2 * T);  // (p, q~) with G_A; (q, p~) with G_B
      V8 acc_x = Splat8(0.0), acc_y = Splat8(0.0);
      for (size_t row = 0; row < terms; ++row) {
        const double* gr = g + row * stride;
        V8 sx0 = Splat8(0.0), sx1 = sx0, sx2 = sx0, sx3 = sx0, sy0 = sx0, sy1 = sx0, sy2 = sx0, sy3 = sx0;
        size_t c = 0;
        for (; c + 4 <= row; c += 4) {
          const double* t = tx + c * R;
          const V8 g0 = Splat8(gr[c]), g1 = Splat8(gr[c + 1]), g2 = Splat8(gr[c + 2]), g3 = Splat8(gr[c + 3]);
          sx0 += g0 * Load8(t);
          sy0 += g0 * Load8(t + T);
          sx1 += g1 * Load8(t + R);
          sy1 += g1 * Load8(t + R + T);
          sx2 += g2 * Load8(t + 2 * R);
          sy2 += g2 * Load8(t + 2 * R + T);
          sx3 += g3 * Load8(t + 3 * R);
          sy3 += g3 * Load8(t + 3 * R + T);
        }
        for (; c < row; ++c) {
          const V8 gv = Splat8(gr[c]);
          sx0 += gv * Load8(tx + c * R);
          sy0 += gv * Load8(tx + c * R + T);
        }
        const V8 sx = (sx0 + sx1) + (sx2 + sx3), sy = (sy0 + sy1) + (sy2 + sy3);
        const V8 gd = Splat8(gr[row]);
        const V8 x = Load8(tx + row * R), y = Load8(tx + row * R + T);
        acc_x += x * (gd * x + 2.0 * sx);
        acc_y += y * (gd * y + 2.0 * sy);
      }
      plus += acc_x;
      minus += acc_y;
    }
    for (size_t l = 0; l < T; ++l) {
      const size_t j = k * T + l;
      if (j >= half) break;
      out[j] = 0.25 * plus[l];
      if (j + 1 < half) out[n_out - 1 - j] = 0.25 * minus[l];
    }
  }
}
#pragma GCC diagnostic pop

}  // namespace detail

IntensityAccumulator::IntensityAccumulator(int max_terms)
    : n_(max_terms),
      stride_((static_cast<size_t>(max_terms) + 7) / 8 * 8),
      ga_(stride_ * stride_, 0.0),
      gb_(stride_ * stride_, 0.0),
      buf_(kBatch * 4 * stride_, 0.0),
      wbuf_(kBatch * 4 * stride_, 0.0),
      slot_len_(kBatch, 0) {
  SKYBAKE_CHECK_GE(max_terms, 1);
}

void IntensityAccumulator::Add(const MieCoefficients& c, double weight) {
  SKYBAKE_CHECK_LE(c.terms, n_);
  if (count_ == kBatch) Flush();
  double* b = buf_.data() + count_ * 4 * stride_;
  double* w = wbuf_.data() + count_ * 4 * stride_;
  const size_t n = static_cast<size_t>(c.terms);
  // The slot may hold a longer earlier radius: zero what this one does not overwrite.
  if (slot_len_[count_] > n) {
    for (size_t k = 0; k < 4; ++k) std::fill(b + k * stride_ + n, b + k * stride_ + slot_len_[count_], 0.0);
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

void IntensityAccumulator::Evaluate(const AngularTables& tables, std::span<double> out) {
  SKYBAKE_CHECK_EQ(out.size(), 2 * tables.half() - 1);
  SKYBAKE_CHECK_LE(used_, tables.max_terms());
  Flush();
  detail::GramEvaluate(ga_.data(), gb_.data(), stride_, static_cast<size_t>(used_), tables.Tile(0),
                       tables.tiles(), static_cast<size_t>(tables.max_terms()) * AngularTables::kRow, tables.half(),
                       out.data());
}

}  // namespace skybake::mie
