// Fast size-averaged scattering intensities: I(theta_j) = sum_r w_r i_r(theta_j) over many radii r
// at every angle of a mirrored grid (phase_grid.h), where i = (|S1|^2 + |S2|^2)/2 (BH eq. 4.77:
// the Mueller element S11 for unpolarised light, = k^2 dC_sca/dOmega).
//
// Reformulation (exact; each step is an identity of the BH series in mie_sphere.h):
//   U = S1 + S2 = sum alpha_n p_n(mu),  V = S1 - S2 = sum beta_n q_n(mu),
//   alpha_n = c_n (a_n + b_n),  beta_n = c_n (a_n - b_n),  c_n = (2n+1)/(n(n+1)),
//   p_n = pi_n + tau_n,  q_n = pi_n - tau_n,
//   |S1|^2 + |S2|^2 = (|U|^2 + |V|^2)/2,  so  i = (|U|^2 + |V|^2)/4.
// Because p_n, q_n are real, |U|^2 = p^T Re(alpha alpha^H) p, and the sum over radii moves inside:
//   sum_r w_r |U_r|^2 = p^T G_A p,  G_A = sum_r w_r (Re alpha_r Re alpha_r^T + Im alpha_r Im alpha_r^T),
//   sum_r w_r |V_r|^2 = q^T G_B q,  G_B likewise with beta.
// The Gram matrices G_A, G_B (N x N, symmetric) take O(N^2) per radius to accumulate; the angles
// are visited once per evaluation, not once per radius: O(N^2 M) per evaluation instead of
// O(N M) per radius (M angles) - about 6x fewer operations for an aerosol mode of 5000 radii.
// Mirror symmetry (BH eq. 4.48: pi_n(-mu) = (-1)^{n-1} pi_n(mu), tau_n(-mu) = (-1)^n tau_n(mu)):
//   p_n(-mu) = (-1)^{n+1} q_n(mu),  q_n(-mu) = (-1)^{n+1} p_n(mu),
// so the angle pi - theta uses the same tables with signs: I(-mu) = (q~^T G_A q~ + p~^T G_B p~)/4,
// p~_n = (-1)^{n+1} p_n, q~_n = (-1)^{n+1} q_n.
// Rounding: a quadratic form squares the cancellation of the amplitude sum; for size-averaged
// intensities that ratio stays below ~1e4 (tests/optics bound the difference to the direct sum of
// mie_sphere.h's Amplitudes at 1e-9 relative).
//
// The tables p_n(mu_j), q_n(mu_j) depend only on the grid; they are built once per table build
// and shared (read-only) by all wavelengths, radii and threads.
//
// Determinism: every matrix element and every angle is a sum in a fixed order (radii in the
// order given, terms in increasing n); vector lanes are independent elements, and the file is
// compiled without contraction into fused multiply-adds, so the bytes do not depend on the CPU's
// vector width (the kernels are compiled for AVX-512, AVX2 and baseline x86-64 and chosen at run
// time).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "optics/mie_sphere.h"
#include "optics/phase_grid.h"

namespace skybake::mie {

class AngularTables {
 public:
  // Angles per tile of the kernels (one AVX-512 register of doubles).
  static constexpr size_t kTile = 8;
  // Per term and tile: p, q~ (used with G_A), q, p~ (used with G_B), kTile values each.
  static constexpr size_t kRow = 4 * kTile;

  AngularTables() = default;
  // p_n, q_n for n = 1..max_terms at the grid's angles in [0, pi/2].
  AngularTables(const PhaseGrid& grid, int max_terms);

  int max_terms() const { return max_terms_; }
  size_t half() const { return half_; }
  size_t tiles() const { return tiles_; }
  // Tile-major layout: for tile k, term n (1-based) at Tile(k) + (n-1) kRow (angles past the end
  // of the grid hold 0).
  const double* Tile(size_t k) const { return data_.data() + k * static_cast<size_t>(max_terms_) * kRow; }

 private:
  int max_terms_ = 0;
  size_t half_ = 0;
  size_t tiles_ = 0;
  std::vector<double> data_;
};

// Running sums G_A, G_B over radii, and their evaluation at the grid angles.
class IntensityAccumulator {
 public:
  explicit IntensityAccumulator(int max_terms);
  // Empty again, for up to max_terms terms (keeps the memory: no new pages to fault in).
  void Reset(int max_terms);

  // G += weight * (the radius' rank-2 terms). Radii are buffered and added in batches (in the
  // order given); Flush() is implied by Scale and Evaluate.
  void Add(const MieCoefficients& c, double weight);
  // G *= factor (the halving of nested trapezoid levels).
  void Scale(double factor);
  // G += other's G (other may hold fewer terms): sums over disjoint sets of radii combine.
  void AddAccumulator(IntensityAccumulator& other);
  // out[j] = sum_r w_r i_r(theta_j) for all 2 half - 1 grid angles.
  void Evaluate(const AngularTables& tables, std::span<double> out);
  int max_terms() const { return n_; }

 private:
  void Flush();

  int n_ = 0;
  size_t stride_ = 0;                // n_ rounded up to a multiple of 16 (row length of G and buffers)
  std::vector<double> ga_, gb_;  // row-major, lower triangle used
  // Buffered radii (added in batches of kBatch, in order): per slot the real and imaginary parts
  // of alpha and beta (buf_) and the same times the weight (wbuf_), 4 arrays of stride_ values,
  // zero beyond the radius' terms.
  static constexpr size_t kBatch = 32;
  size_t count_ = 0;
  int batch_terms_ = 0;
  int used_ = 0;  // largest N added (rows beyond it are zero)
  std::vector<double> buf_, wbuf_;
  std::vector<size_t> slot_len_;  // entries of each slot that may be non-zero
};

// out[j] += weight * i(theta_j) of one sphere at every grid angle by the direct sums U, V above
// (O(N) per angle, no Gram matrix): cheaper than an evaluation of G (O(N^2) per angle) when a
// few spheres are added to intensities known already.
void AddDirectIntensities(const MieCoefficients& c, double weight, const AngularTables& tables, std::span<double> out);

namespace detail {
// The Gram update's kernels (mie_angular.cpp; IntensityAccumulator calls the one the CPU
// supports): the 4 x 16 tile for AVX-512 and the 4 x 4 tile for AVX2 and baseline x86-64. They
// give the same bits (tests/optics/mie_angular_test.cpp). G += sum over the count radii of
// w (x x^T + y y^T), lower triangle, rows < terms; buf and wbuf as in IntensityAccumulator.
__attribute__((target("avx512f"))) void GramUpdateAvx512(double* ga, double* gb, size_t stride, size_t terms,
                                                         const double* buf, const double* wbuf, size_t count);
__attribute__((target("avx2"))) void GramUpdateAvx2(double* ga, double* gb, size_t stride, size_t terms, const double* buf,
                                                    const double* wbuf, size_t count);
void GramUpdateBaseline(double* ga, double* gb, size_t stride, size_t terms, const double* buf, const double* wbuf,
                        size_t count);
// The evaluation's kernels (two 8-angle tiles per pass over G for AVX-512, 4 angles per pass for
// AVX2 and baseline; the same bits): out = the size-averaged |S1|^2 + |S2|^2 at every grid
// angle from G (rows < terms) and the tables' tiles.
__attribute__((target("avx512f"))) void GramEvaluateAvx512(const double* ga, const double* gb, size_t stride, size_t terms,
                                                           const double* tables, size_t tiles, size_t tile_stride,
                                                           size_t half, double* out);
__attribute__((target("avx2"))) void GramEvaluateAvx2(const double* ga, const double* gb, size_t stride, size_t terms,
                                                      const double* tables, size_t tiles, size_t tile_stride, size_t half,
                                                      double* out);
void GramEvaluateBaseline(const double* ga, const double* gb, size_t stride, size_t terms, const double* tables, size_t tiles,
                          size_t tile_stride, size_t half, double* out);
// The direct sums' kernels (AddDirectIntensities; the same bits): per grid angle of the tiles in
// [0, pi/2], plus = |U(+mu)|^2 + |V(+mu)|^2 and minus = |U(-mu)|^2 + |V(-mu)|^2 of one sphere from
// coef (Re alpha, Im alpha, Re beta, Im beta of each of its n terms).
__attribute__((target("avx512f"))) void DirectSumsAvx512(const double* coef, size_t n, const double* tables,
                                                         size_t tiles, size_t tile_stride, double* plus, double* minus);
__attribute__((target("avx2"))) void DirectSumsAvx2(const double* coef, size_t n, const double* tables, size_t tiles,
                                                    size_t tile_stride, double* plus, double* minus);
void DirectSumsBaseline(const double* coef, size_t n, const double* tables, size_t tiles, size_t tile_stride,
                        double* plus, double* minus);
void DirectSums(const double* coef, size_t n, const double* tables, size_t tiles, size_t tile_stride, double* plus,
                double* minus);
}  // namespace detail

}  // namespace skybake::mie
