// CIE colour-matching functions x̄(λ), ȳ(λ), z̄(λ) of the two observers skybake supports
// (docs/color.md §3).
//
//   Observer::kCie2006_2deg (default): the CIE 2006 / CIE 170-2 "physiologically relevant" 2°
//     XYZ CMFs, linear transformations of the CIE 2006 2° LMS cone fundamentals (CVRL
//     "lin2012xyz2e", cvrl.org; atmospheres/data/cie2006_2deg_xyz_cmf_1nm.csv, 390-830 nm at
//     1 nm). The GT7 sky talk uses them ("CIE (2006) 2-deg Color Matching
//     Function"). Their ȳ is the CIE 2008 physiologically relevant luminous
//     efficiency function V_F(λ), not the SI V(λ) of 1924 (docs/color.md §3.2).
//     CVRL (cvrl.ioo.ucl.ac.uk/ciexyzpr.htm): "The official CIE definition is the version
//     provided at 1-nm steps. At this stepsize, the three CMFs have precisely equal integrals, and
//     therefore an equal-energy white has a chromaticity of 0.333, 0.333."
//     The published table starts at 390 nm: skybake defines the functions as 0 below 389 nm
//     and above 831 nm, linear between table points and down to those zeros (see "Between table
//     points" below). At 390 nm x̄, ȳ, z̄ are 3.3e-3, 4.1e-4 and 9.5e-3 of their peaks; an
//     exponential extrapolation of 390-395 nm puts the omitted parts of ∫x̄, ∫ȳ, ∫z̄ at 1.8e-4,
//     2.0e-5 and 8.9e-4 of the totals (computed; docs/color.md §3.1).
//   Observer::kCie1931_2deg: the CIE 1931 standard colorimetric observer, 360-830 nm at 1 nm
//     (CIE 018:2019, DOI 10.25039/CIE.DS.xvudnb9b; atmospheres/data/cie1931_2deg_xyz_cmf_1nm.csv).
//     ȳ is the SI photopic V(λ). Zero below 359 nm and above 831 nm.
//
// Between table points the functions are linear (skybake's choice for 1 nm tables). At each end
// the table is extended by one step with an explicit 0 (389/831 nm for CIE 2006, 359/831 nm for
// CIE 1931), so the interpolant ramps to zero over that step. This makes the exact integral of
// the interpolant equal to the plain 1 nm sum Σ_j c̄(λ_j)·1 nm, the quantity the CIE/CVRL
// normalise and publish (CIE 2006: the three sums are equal, so illuminant E sits at exactly
// x = y = 1/3 on every grid), instead of the trapezoid sum, which would drop half of the end
// samples (for CIE 2006 half of z̄(390 nm) = 0.0185 is 8e-5 of ∫z̄, enough to move E by 1e-5).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "spectrum/grid.h"
#include "spectrum/spectrum.h"

namespace skybake {

enum class Observer { kCie2006_2deg, kCie1931_2deg };

inline constexpr Observer kDefaultObserver = Observer::kCie2006_2deg;

// "cie2006_2deg" / "cie1931_2deg": the names used in YAML and on the command line.
const char* ObserverName(Observer observer);
std::optional<Observer> ParseObserver(std::string_view name);
// The table's file name in atmospheres/data/.
const char* CmfFileName(Observer observer);
// atmospheres/data/<CmfFileName> found by io/repo_paths.h FindRepoFile (for tools run without
// an explicit data folder).
std::filesystem::path DefaultCmfPath(Observer observer);

class Cmf {
 public:
  // Reads columns wavelength_nm, xbar, ybar, zbar (dimensionless, the CIE normalisation:
  // ȳ(555 nm) ≈ 1). Errors (InputError with file:line): missing columns, non-numbers, negative
  // values, wavelengths not strictly increasing.
  static Cmf Load(const std::filesystem::path& csv_path, Observer observer);
  // Loads DefaultCmfPath(observer).
  static Cmf LoadDefault(Observer observer);

  Observer observer() const { return observer_; }
  const std::filesystem::path& path() const { return path_; }
  // The three functions as tables (zero outside their range).
  const TabulatedSpectrum& xbar() const { return bar_[0]; }
  const TabulatedSpectrum& ybar() const { return bar_[1]; }
  const TabulatedSpectrum& zbar() const { return bar_[2]; }
  const TabulatedSpectrum& bar(int c) const { return bar_[c]; }
  // The support of the functions: the table's range extended by one step at each end (nm).
  double min_nm() const { return bar_[1].wavelength_nm.front(); }
  double max_nm() const { return bar_[1].wavelength_nm.back(); }

  // (x̄, ȳ, z̄)(λ): linear between table points, 0 outside.
  std::array<double, 3> Eval(double wavelength_nm) const;
  // ∫ x̄ dλ, ∫ ȳ dλ, ∫ z̄ dλ over all wavelengths (nm), exact for the interpolant, i.e. the
  // plain sums of the 1 nm table (see above).
  std::array<double, 3> Integral() const;
  // (x̄, ȳ, z̄) resampled on `grid` (spectrum.h rules, kAuto: bin averages on grids coarser than
  // 2 nm, values at the samples otherwise).
  std::array<Spectrum, 3> OnGrid(const WavelengthGrid& grid) const;

 private:
  Observer observer_ = kDefaultObserver;
  std::filesystem::path path_;
  std::array<TabulatedSpectrum, 3> bar_;
};

}  // namespace skybake
