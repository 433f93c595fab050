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

// G += sum over the batch of w (x x^T + y y^T) for (x, y) = (Re, Im) of alpha (into ga) and of
// beta (into gb), lower triangle, rows n < terms. buf holds, per batch slot r, the arrays
// [ar, ai, br, bi, w ar, w ai, w br, w bi] of n values each.
__attribute__((target_clones("avx512f", "avx2", "default")))
void GramUpdate(double* ga, double* gb, size_t n, size_t terms, const double* buf, size_t count) {
  for (size_t row = 0; row < terms; ++row) {
    double* ra = ga + row * n;
    double* rb = gb + row * n;
    for (size_t r = 0; r < count; ++r) {
      const double* b = buf + r * 8 * n;
      const double* ar = b;
      const double* ai = b + n;
      const double* br = b + 2 * n;
      const double* bi = b + 3 * n;
      const double war = b[4 * n + row], wai = b[5 * n + row], wbr = b[6 * n + row], wbi = b[7 * n + row];
      for (size_t c = 0; c <= row; ++c) {
        ra[c] += war * ar[c] + wai * ai[c];
        rb[c] += wbr * br[c] + wbi * bi[c];
      }
    }
  }
}

// Eight doubles as one value (GCC vector extension): explicit lanes, so every lane does the same
// operations in the same order whatever the instruction set (one AVX-512 register, two AVX2
// registers or four SSE2 registers).
// (Always inlined into each clone; GCC's -Wpsabi note about passing such values between
// functions compiled for different targets therefore does not apply.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double V8 __attribute__((vector_size(64)));

__attribute__((always_inline)) inline V8 Load8(const double* p) {
  V8 v;
  __builtin_memcpy(&v, p, sizeof(v));
  return v;
}
__attribute__((always_inline)) inline V8 Splat8(double x) { return V8{x, x, x, x, x, x, x, x}; }

// out[j] = (p^T G_A p + q^T G_B q)/4 at +mu_j and (q~^T G_A q~ + p~^T G_B p~)/4 at -mu_j, using
// x^T G x = sum_n x_n (G_nn x_n + 2 sum_{n' < n} G_nn' x_n'); the inner sums run in four
// interleaved partial sums (n' mod 4) to hide the addition latency.
__attribute__((target_clones("avx512f", "avx2", "default")))
void GramEvaluate(const double* ga, const double* gb, size_t n, size_t terms, const double* tables,
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
        const double* gr = g + row * n;
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
      ga_(static_cast<size_t>(max_terms) * max_terms, 0.0),
      gb_(static_cast<size_t>(max_terms) * max_terms, 0.0),
      buf_(kBatch * 8 * static_cast<size_t>(max_terms), 0.0) {
  SKYBAKE_CHECK_GE(max_terms, 1);
}

void IntensityAccumulator::Add(const MieCoefficients& c, double weight) {
  SKYBAKE_CHECK_LE(c.terms, n_);
  if (count_ == kBatch) Flush();
  double* b = buf_.data() + count_ * 8 * static_cast<size_t>(n_);
  const size_t n = static_cast<size_t>(n_);
  // Slots are zero beyond the radius' own terms (they may hold an earlier radius' values).
  std::fill(b, b + 8 * n, 0.0);
  for (int i = 1; i <= c.terms; ++i) {
    const double cn = (2.0 * i + 1.0) / (static_cast<double>(i) * (i + 1.0));
    const Complex alpha = cn * (c.a[i - 1] + c.b[i - 1]);
    const Complex beta = cn * (c.a[i - 1] - c.b[i - 1]);
    const size_t j = static_cast<size_t>(i - 1);
    b[j] = alpha.real();
    b[n + j] = alpha.imag();
    b[2 * n + j] = beta.real();
    b[3 * n + j] = beta.imag();
    b[4 * n + j] = weight * alpha.real();
    b[5 * n + j] = weight * alpha.imag();
    b[6 * n + j] = weight * beta.real();
    b[7 * n + j] = weight * beta.imag();
  }
  batch_terms_ = std::max(batch_terms_, c.terms);
  used_ = std::max(used_, c.terms);
  ++count_;
}

void IntensityAccumulator::Flush() {
  if (count_ == 0) return;
  detail::GramUpdate(ga_.data(), gb_.data(), static_cast<size_t>(n_), static_cast<size_t>(batch_terms_), buf_.data(),
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
  detail::GramEvaluate(ga_.data(), gb_.data(), static_cast<size_t>(n_), static_cast<size_t>(used_), tables.Tile(0),
                       tables.tiles(), static_cast<size_t>(tables.max_terms()) * AngularTables::kRow, tables.half(),
                       out.data());
}

}  // namespace skybake::mie
