// Spectra: tabulated data as read from a CSV, and spectra sampled on a WavelengthGrid, with the
// one resampling rule that connects them (docs/color.md §2).
//
// A tabulated spectrum (TabulatedSpectrum) is a function of wavelength defined by its table: the
// piecewise-linear interpolant through the points (λ_j, f_j), j = 0..m-1. Outside [λ_0, λ_{m-1}]
// it is undefined (an error to ask for), or zero where the table says so (the CIE colour-matching
// functions, spectrum/cmf.h).
//
// Resampling onto a grid (Resample):
//   kBinAverage: f_i = (1/Δλ_i) ∫_{lo_i}^{hi_i} f(λ) dλ over the grid's bin i (spectrum/grid.h),
//     integrating the piecewise-linear interpolant exactly. Then Σ_i f_i Δλ_i equals the
//     trapezoid integral of the table over [lo_0, hi_{n-1}] (conservation; tests check it to
//     1e-12). Use it for data finer than the grid (the ASTM G173 solar spectrum at 0.5-1 nm onto
//     a 5 nm grid: each 5 nm sample is the mean irradiance of its bin [λ-2.5, λ+2.5] nm).
//     Note: Bruneton 2017's demo averages the *samples* in [λ, λ+10) instead (not centred, and
//     a mean of samples rather than an integral); on the same bins the two averages of ASTM G173
//     differ by up to 1.9 % (computed, docs/color.md §2).
//   kLinear: f_i = f(λ_i), the interpolant at the sample (data as fine as or coarser than the
//     grid; exact on the table's own points).
//   kAuto: kBinAverage when the table resolves every bin, i.e. its largest spacing inside the
//     covered range is at most half the narrowest bin (two table intervals per bin or more);
//     kLinear otherwise. So 1 nm data onto a 5 nm grid is bin-averaged and 1 nm data onto a 1 nm
//     grid is copied as is.
// Coverage: every bin (kBinAverage) or sample (kLinear) must lie inside the table unless the
// table is zero outside; otherwise InputError(table file) says which range is missing.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/csv.h"
#include "spectrum/grid.h"

namespace skybake {

struct TabulatedSpectrum {
  std::string display_name;          // the file it came from, for messages
  std::string source;                // the file's "# source:" line
  std::string quantity;              // the column name, which carries the unit (e.g. "extraterrestrial_W_m2_nm")
  std::vector<double> wavelength_nm;  // strictly increasing
  std::vector<double> values;
  // Outside the table: an error (false) or zero (true; the CMFs, docs/color.md §3).
  bool zero_outside = false;

  // The interpolant at λ: linear between table points; 0 outside when zero_outside, else
  // InternalError (callers check coverage first).
  double Eval(double wavelength_nm) const;
  // Exact ∫_{a}^{b} f(λ) dλ of the interpolant (a <= b), zero outside when zero_outside; nm·[f].
  double Integral(double a_nm, double b_nm) const;
  // Largest spacing between consecutive table wavelengths that overlap [a, b] (nm).
  double MaxSpacingWithin(double a_nm, double b_nm) const;
};

struct Spectrum {
  WavelengthGrid grid;
  std::vector<double> values;  // one per grid sample
  std::string quantity;        // as TabulatedSpectrum::quantity
};

enum class Resampling { kAuto, kBinAverage, kLinear };

// Reads the column `value_column` of a spectral CSV (io/csv.h conventions) against its
// wavelength column, found as "wavelength_<unit>" with a wavelength unit (_nm, _um; converted to
// nm). Checks, reported together with file:line: the columns exist, every cell is a finite
// number, wavelengths strictly increase, and (when require_non_negative) values are >= 0.
TabulatedSpectrum LoadSpectrumColumn(const std::filesystem::path& csv_path, const std::string& value_column,
                                     bool require_non_negative = true);
// The same from an already parsed table (tests, tables with several columns).
TabulatedSpectrum SpectrumColumn(const CsvTable& table, const std::string& value_column,
                                 bool require_non_negative = true);

// Samples `table` on `grid` by `rule` (see above). Throws InputError(table.display_name) when
// the table does not cover what the grid needs; kBinAverage on a table coarser than the grid is
// allowed (it is exact for the interpolant) but kAuto would not choose it.
Spectrum Resample(const TabulatedSpectrum& table, const WavelengthGrid& grid, Resampling rule = Resampling::kAuto);
// Which rule kAuto picks for this table and grid.
Resampling ChooseResampling(const TabulatedSpectrum& table, const WavelengthGrid& grid);

}  // namespace skybake
