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

// The slab's twilight rows in one pass: lo[e] = wv[0] v[0][e] + wv[1] v[1][e] and hi[e] from the
// corners 2 and 3, each summed from 0 as Gather16 sums, and sum[e] = lo[e] + hi[e], for e < n.
void GatherLoHi(const float* const* v, const float* wv, size_t n, float* lo, float* hi, float* sum);

// A transport cell's step in one pass: acc[w] += gm[w] * j[w], j[w] = sum_{b < 4} ws[b] v[b][w]
// summed as Gather16 sums (from 0, in b order). Each lane's operations are those of Gather16 into
// a buffer and the product added after it: the same bits without the buffer's round trip.
void AccumulateCorners4(const float* const* v, const float* ws, const float* gm, size_t nw, float* acc);
// The same in twilight: lo and hi gathered from vl and vh (the lower and the upper radius's
// corners), j[w] = lo[w] f0[w] + hi[w] f1[w] with f0[w] = c0[w] + (c0[w + nw] - c0[w]) tb and f1
// likewise from c1 (LogBlend's factors at t = tb between two tabulated bins, transport.h).
void AccumulateCorners4LogLin(const float* const* vl, const float* const* vh, const float* ws, const float* c0, const float* c1,
                              float tb, const float* gm, size_t nw, float* acc);

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
