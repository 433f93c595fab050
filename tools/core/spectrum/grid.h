// Wavelength grids: where skybake samples spectra (docs/color.md §1).
//
// A grid is a list of wavelengths λ_i in nm (vacuum wavelengths as tabulated by the CIE and ASTM;
// the air/vacuum difference, ~0.15 nm in the visible, is below every table's resolution). Each
// sample owns a *bin* [lo_i, hi_i] of width Δλ_i = hi_i - lo_i:
//
//   spectral grids (uniform or an explicit list, strictly increasing):
//     the bins are the cells between the midpoints of neighbouring samples; the first and last
//     bins extend half a spacing beyond the end samples:
//       lo_0 = λ_0 - (λ_1 - λ_0)/2,   lo_i = hi_{i-1} = (λ_{i-1} + λ_i)/2,
//       hi_{n-1} = λ_{n-1} + (λ_{n-1} - λ_{n-2})/2.
//     On a uniform grid every bin is [λ_i - h/2, λ_i + h/2] with Δλ_i = h, e.g. 360-830 nm at
//     5 nm: bins [357.5, 362.5], [362.5, 367.5], ..., [827.5, 832.5]. These bins are the
//     quadrature of the spectral integrals (spectrum/xyz.h: ∫ f dλ ≈ Σ f_i Δλ_i, the CIE 15:2004
//     §7.1 summation rule) and the cells over which finer data are bin-averaged
//     (spectrum/spectrum.h), so that Σ f_i Δλ_i conserves the integral of bin-averaged data.
//     A one-sample uniform grid (min = max) has the bin [λ - h/2, λ + h/2].
//
//   the "RGB" grid {680, 550, 440} nm (R, G, B order, as Bruneton & Neyret 2008 §2.1 and
//     Hillaire 2016 §2.1 use for three-channel models; Bruneton 2017 demo.cc):
//     not a quadrature grid. Its
//     values are the three channels of a simplified model, read as Linear Rec.709 (sRGB)
//     (docs/color.md §5). Its bins are 10 nm wide, centred ([675, 685], [545, 555],
//     [435, 445]), used only to bin-average finer data such as the solar spectrum (whose
//     Fraunhofer lines make single 1 nm samples unrepresentative); XyzWeights refuses this grid.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "io/error.h"

namespace skybake {

class WavelengthGrid {
 public:
  enum class Kind { kUniform, kList, kRgb };

  // Width of each bin of the RGB grid (nm).
  static constexpr double kRgbBinWidthNm = 10.0;

  // λ_i = min + i·step for i = 0..n-1, n = (max - min)/step + 1. Requires 0 < min <= max,
  // step > 0 and (max - min)/step an integer within 1e-9 (so that max is a sample). Violations
  // throw InputError located at `where` (the YAML key the numbers came from).
  static WavelengthGrid Uniform(double min_nm, double max_nm, double step_nm, const FileLoc& where = {});
  // An explicit list: at least 2 wavelengths, strictly increasing, all > 0 (InputError at `where`).
  static WavelengthGrid List(std::vector<double> wavelengths_nm, const FileLoc& where = {});
  // The three-channel grid {680, 550, 440} nm.
  static WavelengthGrid Rgb();

  Kind kind() const { return kind_; }
  // True for uniform and list grids (a quadrature over wavelength), false for the RGB grid.
  bool is_spectral() const { return kind_ != Kind::kRgb; }
  size_t size() const { return wavelength_nm_.size(); }
  double operator[](size_t i) const { return wavelength_nm_[i]; }
  const std::vector<double>& wavelength_nm() const { return wavelength_nm_; }
  // The step of a uniform grid (nm); 0 for the other kinds.
  double step_nm() const { return step_nm_; }

  double bin_lo_nm(size_t i) const { return bin_lo_nm_[i]; }
  double bin_hi_nm(size_t i) const { return bin_hi_nm_[i]; }
  double bin_width_nm(size_t i) const { return bin_hi_nm_[i] - bin_lo_nm_[i]; }
  // Smallest bin_lo and largest bin_hi: the wavelength range the grid's bins cover.
  double covered_lo_nm() const;
  double covered_hi_nm() const;

  // For provenance and axis descriptions, e.g. "uniform 360-830 nm, step 5 nm (95 samples; bins
  // centred on the samples)", "list of 4 wavelengths 440, 550, 680, 700 nm", "RGB 680, 550, 440 nm".
  std::string Describe() const;

  bool operator==(const WavelengthGrid& other) const {
    return kind_ == other.kind_ && step_nm_ == other.step_nm_ && wavelength_nm_ == other.wavelength_nm_;
  }

  // An empty grid (size 0), only so that structs holding a grid can be default-constructed;
  // make real grids with the factories above.
  WavelengthGrid() = default;

 private:
  void SetMidpointBins();

  Kind kind_ = Kind::kList;
  double step_nm_ = 0.0;
  std::vector<double> wavelength_nm_;
  std::vector<double> bin_lo_nm_, bin_hi_nm_;
};

}  // namespace skybake
