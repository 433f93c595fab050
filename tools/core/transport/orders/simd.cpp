#include "transport/orders/simd.h"

#include <cstring>

#if defined(__F16C__)
#include <immintrin.h>
#endif

#include <Imath/half.h>

namespace skybake::orders {

namespace {

using V8 = float __attribute__((vector_size(32)));
inline V8 LoadV8(const float* p) {
  V8 x;
  std::memcpy(&x, p, sizeof x);
  return x;
}
inline void StoreV8(float* p, V8 x) { std::memcpy(p, &x, sizeof x); }
// 8 binary16 values as floats (exact): vcvtph2ps where the build has F16C, else one by one by
// Imath's conversion (itself F16C's where the build has it).
inline V8 LoadV8(const uint16_t* p) {
  V8 x;
#if defined(__F16C__)
  const __m256 f = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
  std::memcpy(&x, &f, sizeof x);
#else
  for (int i = 0; i < 8; ++i) x[i] = imath_half_to_float(p[i]);
#endif
  return x;
}
inline float ValueOf(float v) { return v; }
inline float ValueOf(uint16_t v) { return imath_half_to_float(v); }

// acc[b * nw + w] (+)= sum_{j ascending < n} g_j x[b * b_stride + j * x_stride + w] for the 4 b of a
// sun block, g_j = g[j * g_stride + w] (kScalar false: a row per j, loaded once for the 4 b) or
// g[j * g_stride] (kScalar true: one weight per j).
template <bool kAdd, bool kScalar, class G>
void ModalBlock4Impl(const G* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                     float* acc) {
  size_t w = 0;
  for (; w + 8 <= nw; w += 8) {
    V8 a0 = {}, a1 = {}, a2 = {}, a3 = {};
    if (kAdd) {
      a0 = LoadV8(acc + w), a1 = LoadV8(acc + nw + w), a2 = LoadV8(acc + 2 * nw + w), a3 = LoadV8(acc + 3 * nw + w);
    }
    for (size_t j = 0; j < n; ++j) {
      V8 gv;
      if (kScalar) {
        gv = V8{} + ValueOf(g[j * g_stride]);  // the weight in every lane
      } else {
        gv = LoadV8(g + j * g_stride + w);
      }
      const float* xj = x + j * x_stride + w;
      a0 += gv * LoadV8(xj);
      a1 += gv * LoadV8(xj + b_stride);
      a2 += gv * LoadV8(xj + 2 * b_stride);
      a3 += gv * LoadV8(xj + 3 * b_stride);
    }
    StoreV8(acc + w, a0);
    StoreV8(acc + nw + w, a1);
    StoreV8(acc + 2 * nw + w, a2);
    StoreV8(acc + 3 * nw + w, a3);
  }
  for (; w < nw; ++w) {
    for (size_t b = 0; b < 4; ++b) {
      float a = kAdd ? acc[b * nw + w] : 0.0f;
      for (size_t j = 0; j < n; ++j) a += ValueOf(g[j * g_stride + (kScalar ? 0 : w)]) * x[b * b_stride + j * x_stride + w];
      acc[b * nw + w] = a;
    }
  }
}

}  // namespace

void Gather16(const float* const* v, const float* wv, int k0, int k1, size_t nw, float* out) {
  size_t w = 0;
  for (; w + 8 <= nw; w += 8) {
    V8 sum = {};
    for (int k = k0; k < k1; ++k) {
      V8 x;
      std::memcpy(&x, v[k] + w, sizeof x);
      sum += wv[k] * x;
    }
    std::memcpy(out + w, &sum, sizeof sum);
  }
  for (; w < nw; ++w) {
    float sum = 0.0f;
    for (int k = k0; k < k1; ++k) sum += wv[k] * v[k][w];
    out[w] = sum;
  }
}

namespace {

// sum_{b < 4} ws[b] v[b][w .. w + 7], from 0 in b order (Gather16's sum).
inline V8 Corners4V8(const float* const* v, const float* ws, size_t w) {
  V8 sum = {};
  for (int b = 0; b < 4; ++b) sum += ws[b] * LoadV8(v[b] + w);
  return sum;
}
inline float Corners4(const float* const* v, const float* ws, size_t w) {
  float sum = 0.0f;
  for (int b = 0; b < 4; ++b) sum += ws[b] * v[b][w];
  return sum;
}

}  // namespace

void GatherLoHi(const float* const* v, const float* wv, size_t n, float* lo, float* hi, float* sum) {
  size_t e = 0;
  for (; e + 8 <= n; e += 8) {
    V8 l = {}, h = {};
    l += wv[0] * LoadV8(v[0] + e);
    l += wv[1] * LoadV8(v[1] + e);
    h += wv[2] * LoadV8(v[2] + e);
    h += wv[3] * LoadV8(v[3] + e);
    StoreV8(lo + e, l);
    StoreV8(hi + e, h);
    StoreV8(sum + e, l + h);
  }
  for (; e < n; ++e) {
    float l = 0.0f, h = 0.0f;
    l += wv[0] * v[0][e];
    l += wv[1] * v[1][e];
    h += wv[2] * v[2][e];
    h += wv[3] * v[3][e];
    lo[e] = l, hi[e] = h, sum[e] = l + h;
  }
}

void AccumulateCorners4(const float* const* v, const float* ws, const float* gm, size_t nw, float* acc) {
  size_t w = 0;
  for (; w + 8 <= nw; w += 8) StoreV8(acc + w, LoadV8(acc + w) + LoadV8(gm + w) * Corners4V8(v, ws, w));
  for (; w < nw; ++w) acc[w] += gm[w] * Corners4(v, ws, w);
}

void AccumulateCorners4LogLin(const float* const* vl, const float* const* vh, const float* ws, const float* c0, const float* c1,
                              float tb, const float* gm, size_t nw, float* acc) {
  size_t w = 0;
  for (; w + 8 <= nw; w += 8) {
    const V8 c0w = LoadV8(c0 + w), c1w = LoadV8(c1 + w);
    const V8 f0 = c0w + (LoadV8(c0 + nw + w) - c0w) * tb, f1 = c1w + (LoadV8(c1 + nw + w) - c1w) * tb;
    const V8 j = Corners4V8(vl, ws, w) * f0 + Corners4V8(vh, ws, w) * f1;
    StoreV8(acc + w, LoadV8(acc + w) + LoadV8(gm + w) * j);
  }
  for (; w < nw; ++w) {
    const float f0 = c0[w] + (c0[w + nw] - c0[w]) * tb, f1 = c1[w] + (c1[w + nw] - c1[w]) * tb;
    acc[w] += gm[w] * (Corners4(vl, ws, w) * f0 + Corners4(vh, ws, w) * f1);
  }
}

void ModalAnalysis(const float* l, const float* cos_mq, size_t nm, size_t nq, size_t nw, float* out, size_t out_stride) {
  size_t m = 0;
  for (; m + 4 <= nm; m += 4) {
    size_t w = 0;
    for (; w + 8 <= nw; w += 8) {
      V8 a0 = {}, a1 = {}, a2 = {}, a3 = {};
      for (size_t q = 0; q < nq; ++q) {
        const V8 x = LoadV8(l + q * nw + w);
        a0 += cos_mq[m * nq + q] * x;
        a1 += cos_mq[(m + 1) * nq + q] * x;
        a2 += cos_mq[(m + 2) * nq + q] * x;
        a3 += cos_mq[(m + 3) * nq + q] * x;
      }
      StoreV8(out + m * out_stride + w, a0);
      StoreV8(out + (m + 1) * out_stride + w, a1);
      StoreV8(out + (m + 2) * out_stride + w, a2);
      StoreV8(out + (m + 3) * out_stride + w, a3);
    }
    for (; w < nw; ++w) {
      for (size_t i = 0; i < 4; ++i) {
        float a = 0.0f;
        for (size_t q = 0; q < nq; ++q) a += cos_mq[(m + i) * nq + q] * l[q * nw + w];
        out[(m + i) * out_stride + w] = a;
      }
    }
  }
  for (; m < nm; ++m) {
    for (size_t w = 0; w < nw; ++w) {
      float a = 0.0f;
      for (size_t q = 0; q < nq; ++q) a += cos_mq[m * nq + q] * l[q * nw + w];
      out[m * out_stride + w] = a;
    }
  }
}

void ModalBlock4(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw, float* acc) {
  ModalBlock4Impl<false, false>(g, g_stride, x, x_stride, b_stride, n, nw, acc);
}
void ModalBlock4Add(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                    float* acc) {
  ModalBlock4Impl<true, false>(g, g_stride, x, x_stride, b_stride, n, nw, acc);
}
void ModalBlock4(const uint16_t* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw, float* acc) {
  ModalBlock4Impl<false, false>(g, g_stride, x, x_stride, b_stride, n, nw, acc);
}
void ModalBlock4Add(const uint16_t* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                    float* acc) {
  ModalBlock4Impl<true, false>(g, g_stride, x, x_stride, b_stride, n, nw, acc);
}
void ModalSynthesis4(const float* c, size_t c_stride, const float* t, size_t b_stride, size_t nm, size_t nw, float* acc) {
  ModalBlock4Impl<false, true>(c, c_stride, t, nw, b_stride, nm, nw, acc);
}

}  // namespace skybake::orders
