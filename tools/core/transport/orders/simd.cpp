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
