// Spectral radiance -> CIE XYZ, absolutely normalised (docs/color.md §4).
//
//   X = K_m ∫ x̄(λ) L_λ(λ) dλ,   Y = K_m ∫ ȳ(λ) L_λ(λ) dλ,   Z = K_m ∫ z̄(λ) L_λ(λ) dλ
//
// with K_m = 683 lm/W (the SI definition of the candela: a monochromatic source at 540e12 Hz of
// 1/683 W/sr has 1 cd; BIPM SI Brochure, 9th ed. 2019, §2.3.1. CIE 15:2004 §7.1 uses 683.002 lm/W
// to place V(555 nm) = 1; the difference, 3e-6, is below every table's precision). For spectral
// radiance L_λ in W m^-2 sr^-1 nm^-1, Y is the luminance in cd/m² (and X, Z are on the same
// scale); for spectral irradiance E_λ in W m^-2 nm^-1, Y is the illuminance in lux. No other
// normalisation is applied: there is no "k = 100/∫S ȳ" of reflectance colorimetry.
//
// Quadrature on a spectral WavelengthGrid (grid.h): the integral is the sum over the grid's
// bins, ∫ f(λ) L(λ) dλ ≈ Σ_i c̄_i L_i Δλ_i, where c̄_i is the CMF on the grid (Cmf::OnGrid: the
// bin average ∫_bin c̄ dλ / Δλ_i on grids coarser than the 1 nm table, the value at λ_i on finer
// grids). So the precomputed weights are
//
//   w_x[i] = K_m · x̄_i · Δλ_i,   w_y[i] = K_m · ȳ_i · Δλ_i,   w_z[i] = K_m · z̄_i · Δλ_i   [lm W^-1 nm]
//
// and XYZ = (w_x·L, w_y·L, w_z·L) are three dot products. With bin-averaged CMFs the sum is exact
// whenever L is constant over each bin; for a constant L = 1 W m^-2 sr^-1 nm^-1 it gives
// Y = K_m ∫ȳ dλ exactly on any grid whose bins cover the CMF's range (tests check this and
// the 1 nm sums published for the CMF tables).
//
// Which XYZ: the result is the XYZ of the chosen observer, with no chromatic adaptation (an
// equal-energy spectrum has x = y = 1/3 for both observers). How it enters the OCIO config's
// CIE-XYZ-D65 reference is color/color.h's XyzColorSpace(observer): identity for CIE 1931 2°, a
// D65-matching diagonal for CIE 2006 2° (docs/color.md §6).
//
// Thread safety: XyzWeights is immutable after construction; share one per grid among threads.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "spectrum/cmf.h"
#include "spectrum/grid.h"
#include "spectrum/spectrum.h"

namespace skybake {

// lm/W, the luminous efficacy of 540e12 Hz radiation (SI definition of the candela).
inline constexpr double kMaxLuminousEfficacyLmPerW = 683.0;

struct Xyz {
  double X = 0.0, Y = 0.0, Z = 0.0;
};

struct Chromaticity {
  double x = 0.0, y = 0.0;
};

// x = X/(X+Y+Z), y = Y/(X+Y+Z) (CIE 15:2004 §7.3); (0, 0) for X+Y+Z = 0.
Chromaticity ToChromaticity(const Xyz& xyz);

class XyzWeights {
 public:
  // Precomputes w_x, w_y, w_z for a spectral grid (InternalError for the RGB grid, which is not a
  // quadrature: its three values are Linear Rec.709 channels, docs/color.md §5).
  XyzWeights(const WavelengthGrid& grid, const Cmf& cmf);

  const WavelengthGrid& grid() const { return grid_; }
  Observer observer() const { return observer_; }
  size_t size() const { return wx_.size(); }
  // lm W^-1 nm per sample.
  const std::vector<double>& wx() const { return wx_; }
  const std::vector<double>& wy() const { return wy_; }
  const std::vector<double>& wz() const { return wz_; }

  // XYZ of spectral radiance (W m^-2 sr^-1 nm^-1 -> cd/m²) or irradiance (W m^-2 nm^-1 -> lx)
  // sampled on grid(); values.size() must equal grid().size().
  Xyz Integrate(std::span<const double> values) const;
  Xyz Integrate(std::span<const float> values) const;

 private:
  WavelengthGrid grid_;
  Observer observer_;
  std::vector<double> wx_, wy_, wz_;
};

// XYZ of a Spectrum; its grid must equal weights.grid() (InternalError otherwise).
Xyz SpectrumToXyz(const XyzWeights& weights, const Spectrum& spectrum);

// ---------------------------------------------------------------------------------------------
// Hero wavelengths for a Monte-Carlo spectral renderer (Wilkie, Nawaz, Droske, Weidlich &
// Hanika 2014, "Hero Wavelength Spectral Sampling", Computer Graphics Forum 33(4), EGSR: one
// random "hero" wavelength plus K-1 others at equal rotations of the spectral range, carried by
// the same path), here on the grid's samples so that every optical table is used at its own
// wavelengths (no interpolation between wavelengths).
//
// Given one uniform random number u in [0, 1) and K >= 1, the K grid indices are
//   i_k = floor(frac(u + k/K) · N),   k = 0..K-1,   N = grid size,
// i.e. K equally spaced offsets rotated by u over the grid's index range (when K divides N, the
// indices are i_0 + k N/K mod N exactly). Each i_k alone is uniformly distributed over 0..N-1
// (frac(u + k/K) is uniform on [0, 1) when u is), so with the per-wavelength weights
//   W_k = (N / K) · (w_x, w_y, w_z)[i_k]
// the estimator  XYZ^ = Σ_k W_k · L(λ_{i_k})  has expectation Σ_i w[i] L_i, the deterministic
// grid quadrature above (E[N w[i_k] L_{i_k}] = Σ_i w[i] L_i for each k, averaged over K), for
// any K. With K = N every sample is used once and the estimate is the quadrature exactly.
// (A renderer whose path is chosen by the hero wavelength weights the others by Wilkie's
// multiple-importance-sampling ratio; that belongs to the renderer.)
// ---------------------------------------------------------------------------------------------
inline constexpr int kMaxHeroWavelengths = 16;

struct HeroWavelengths {
  int count = 0;
  std::array<int, kMaxHeroWavelengths> index{};              // grid sample indices
  std::array<double, kMaxHeroWavelengths> wavelength_nm{};   // grid[index]
  std::array<Xyz, kMaxHeroWavelengths> weight{};             // W_k, lm W^-1 nm per unit L
};

// The K = count wavelengths for the random number u (clamped into [0, 1)); 1 <= count <=
// kMaxHeroWavelengths. No allocation; safe to call from many threads on one XyzWeights.
HeroWavelengths SampleHeroWavelengths(const XyzWeights& weights, double u, int count);

}  // namespace skybake
