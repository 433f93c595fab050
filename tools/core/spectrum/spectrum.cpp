#include "spectrum/spectrum.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "io/interp.h"

namespace skybake {

namespace {
std::string Num(double v) { return fmt::format("{}", v); }
}  // namespace

double TabulatedSpectrum::Eval(double w) const {
  const std::vector<double>& x = wavelength_nm;
  SKYBAKE_CHECK(!x.empty());
  if (w < x.front() || w > x.back()) {
    if (zero_outside) return 0.0;
    detail::CheckFailed(__FILE__, __LINE__,
                        fmt::format("{}: wavelength {} nm outside the table [{}, {}] nm", display_name, w, x.front(), x.back()));
  }
  if (x.size() == 1) return values[0];
  const size_t j = FindInterval(x, w);
  const double t = (w - x[j]) / (x[j + 1] - x[j]);
  return values[j] + (values[j + 1] - values[j]) * t;
}

// ∫ of the piecewise-linear interpolant: on each table interval [x_j, x_j+1] that overlaps
// [a, b], the overlap [p, q] contributes (q - p)(f(p) + f(q))/2, exact for a linear piece.
double TabulatedSpectrum::Integral(double a, double b) const {
  const std::vector<double>& x = wavelength_nm;
  SKYBAKE_CHECK_LE(a, b);
  SKYBAKE_CHECK_GE(x.size(), size_t{2});
  if (!zero_outside) {
    const double tol = 1e-9 * std::max(1.0, x.back() - x.front());
    if (a < x.front() - tol || b > x.back() + tol) {
      detail::CheckFailed(__FILE__, __LINE__,
                          fmt::format("{}: integral over [{}, {}] nm outside the table [{}, {}] nm", display_name, a, b,
                                      x.front(), x.back()));
    }
  }
  const double lo = std::max(a, x.front());
  const double hi = std::min(b, x.back());
  if (!(hi > lo)) return 0.0;
  double sum = 0.0;
  for (size_t j = FindInterval(x, lo); j + 1 < x.size() && x[j] < hi; ++j) {
    const double p = std::max(lo, x[j]);
    const double q = std::min(hi, x[j + 1]);
    if (!(q > p)) continue;
    const double slope = (values[j + 1] - values[j]) / (x[j + 1] - x[j]);
    const double fp = values[j] + slope * (p - x[j]);
    const double fq = values[j] + slope * (q - x[j]);
    sum += 0.5 * (fp + fq) * (q - p);
  }
  return sum;
}

double TabulatedSpectrum::MaxSpacingWithin(double a, double b) const {
  const std::vector<double>& x = wavelength_nm;
  double worst = 0.0;
  for (size_t j = 0; j + 1 < x.size(); ++j) {
    if (x[j + 1] <= a || x[j] >= b) continue;  // interval does not overlap (a, b)
    worst = std::max(worst, x[j + 1] - x[j]);
  }
  return worst;
}

TabulatedSpectrum SpectrumColumn(const CsvTable& table, const std::string& value_column, bool require_non_negative) {
  Diagnostics diags;
  std::optional<CsvTable::SiColumn> wl = table.ColumnIn("wavelength", Quantity::kWavelength, diags);
  std::vector<double> values = table.Numbers(value_column, diags);
  diags.ThrowIfAny();
  TabulatedSpectrum s;
  s.display_name = table.display_name();
  s.source = table.source();
  s.quantity = value_column;
  s.wavelength_nm = wl->values;
  s.values = std::move(values);
  for (size_t r = 0; r < table.rows(); ++r) {
    if (!(s.wavelength_nm[r] > 0.0)) {
      diags.Add(table.LocOfRow(r), fmt::format("column '{}': wavelength must be > 0, got {}", wl->name, table.cell(r, table.ColumnIndex(wl->name))));
    }
    if (r > 0 && !(s.wavelength_nm[r] > s.wavelength_nm[r - 1])) {
      diags.Add(table.LocOfRow(r), fmt::format("column '{}': wavelengths must strictly increase, but {} follows {}", wl->name,
                                               table.cell(r, table.ColumnIndex(wl->name)),
                                               table.cell(r - 1, table.ColumnIndex(wl->name))));
    }
    if (require_non_negative && s.values[r] < 0.0) {
      diags.Add(table.LocOfRow(r), fmt::format("column '{}': expected a value >= 0, got {}", value_column,
                                               table.cell(r, table.ColumnIndex(value_column))));
    }
  }
  if (s.wavelength_nm.size() < 2) diags.Add(table.LocOfHeader(), "a spectrum needs at least 2 rows");
  diags.ThrowIfAny();
  return s;
}

TabulatedSpectrum LoadSpectrumColumn(const std::filesystem::path& csv_path, const std::string& value_column,
                                     bool require_non_negative) {
  return SpectrumColumn(CsvTable::Load(csv_path), value_column, require_non_negative);
}

Resampling ChooseResampling(const TabulatedSpectrum& table, const WavelengthGrid& grid) {
  double narrowest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < grid.size(); ++i) narrowest = std::min(narrowest, grid.bin_width_nm(i));
  const double spacing = table.MaxSpacingWithin(grid.covered_lo_nm(), grid.covered_hi_nm());
  return spacing > 0.0 && spacing <= 0.5 * narrowest ? Resampling::kBinAverage : Resampling::kLinear;
}

Spectrum Resample(const TabulatedSpectrum& table, const WavelengthGrid& grid, Resampling rule) {
  SKYBAKE_CHECK_GE(table.wavelength_nm.size(), size_t{2});
  if (rule == Resampling::kAuto) rule = ChooseResampling(table, grid);
  const double t_lo = table.wavelength_nm.front(), t_hi = table.wavelength_nm.back();
  const double tol = 1e-9 * std::max(1.0, t_hi - t_lo);
  if (!table.zero_outside) {
    double need_lo = 0.0, need_hi = 0.0;
    if (rule == Resampling::kBinAverage) {
      need_lo = grid.covered_lo_nm();
      need_hi = grid.covered_hi_nm();
    } else {
      need_lo = *std::min_element(grid.wavelength_nm().begin(), grid.wavelength_nm().end());
      need_hi = *std::max_element(grid.wavelength_nm().begin(), grid.wavelength_nm().end());
    }
    if (need_lo < t_lo - tol || need_hi > t_hi + tol) {
      throw InputError(FileLoc{table.display_name, 0},
                       fmt::format("column '{}' covers {}-{} nm, but the wavelength grid ({}) needs {}-{} nm{}",
                                   table.quantity, Num(t_lo), Num(t_hi), grid.Describe(), Num(need_lo), Num(need_hi),
                                   rule == Resampling::kBinAverage ? " (its bins, bin-averaged)" : ""));
    }
  }
  Spectrum out{grid, std::vector<double>(grid.size()), table.quantity};
  for (size_t i = 0; i < grid.size(); ++i) {
    if (rule == Resampling::kBinAverage) {
      // Clamp the bin to the table by the tolerance above so that a grid ending exactly at the
      // table's end (up to rounding) is accepted.
      double lo = grid.bin_lo_nm(i), hi = grid.bin_hi_nm(i);
      if (!table.zero_outside) {
        lo = std::max(lo, t_lo);
        hi = std::min(hi, t_hi);
      }
      out.values[i] = table.Integral(lo, hi) / grid.bin_width_nm(i);
    } else {
      double w = grid[i];
      if (!table.zero_outside) w = std::clamp(w, t_lo, t_hi);
      out.values[i] = table.Eval(w);
    }
  }
  return out;
}

}  // namespace skybake
