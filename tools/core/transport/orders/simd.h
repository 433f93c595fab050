// The solve's innermost products, 8 wavelengths at a time in GCC vectors (one register with AVX2,
// two with SSE2) with the sums kept in registers. Each lane rounds exactly as the plain scalar loop
// it replaces (contraction is off: CMakeLists.txt, SKYBAKE_SIMD), and every sum runs in the order
// of that loop, so the bytes are those of the plain form.
#pragma once

#include <cstddef>
#include <cstdint>

namespace skybake::orders {

// out[w] = sum_{k in [k0, k1)} wv[k] v[k][w], summed in k order: the transport's gather of J at a
// table ray's step.
void Gather16(const float* const* v, const float* wv, int k0, int k1, size_t nw, float* out);

// The modal scatter's three products (modal_kernel.cpp).
// out[m * out_stride + w] = sum_{q ascending} cos_mq[m * nq + q] l[q * nw + w], m < nm.
void ModalAnalysis(const float* l, const float* cos_mq, size_t nm, size_t nq, size_t nw, float* out, size_t out_stride);
// acc[b * nw + w] = sum_{j ascending < n} g[j * g_stride + w] x[b * b_stride + j * x_stride + w] for the 4 b of a sun block.
void ModalBlock4(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw, float* acc);
// The same added to acc.
void ModalBlock4Add(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                    float* acc);
// The two with g stored as binary16 (Imath's half; converted exactly, so each sum rounds as with the
// float g of the same values).
void ModalBlock4(const uint16_t* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw, float* acc);
void ModalBlock4Add(const uint16_t* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                    float* acc);
// acc[b * nw + w] = sum_{m ascending < nm} c[m * c_stride] t[b * b_stride + m * nw + w], 4 b.
void ModalSynthesis4(const float* c, size_t c_stride, const float* t, size_t b_stride, size_t nm, size_t nw, float* acc);

}  // namespace skybake::orders
