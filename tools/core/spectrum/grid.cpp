#include "spectrum/grid.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace skybake {

namespace {
// Shortest decimal that round-trips ("5", "357.5", "0.1").
std::string Num(double v) { return fmt::format("{}", v); }
}  // namespace

WavelengthGrid WavelengthGrid::Uniform(double min_nm, double max_nm, double step_nm, const FileLoc& where) {
  if (!(std::isfinite(min_nm) && std::isfinite(max_nm) && std::isfinite(step_nm))) {
    throw InputError(where, "wavelength grid: min_nm, max_nm and step_nm must be finite numbers");
  }
  if (!(min_nm > 0.0)) throw InputError(where, fmt::format("wavelength grid: min_nm must be > 0, got {}", Num(min_nm)));
  if (!(max_nm >= min_nm)) {
    throw InputError(where, fmt::format("wavelength grid: max_nm ({}) must be >= min_nm ({})", Num(max_nm), Num(min_nm)));
  }
  if (!(step_nm > 0.0)) throw InputError(where, fmt::format("wavelength grid: step_nm must be > 0, got {}", Num(step_nm)));
  const double intervals = (max_nm - min_nm) / step_nm;
  const double n_intervals = std::round(intervals);
  if (std::abs(intervals - n_intervals) > 1e-9 * std::max(1.0, n_intervals)) {
    throw InputError(where, fmt::format("wavelength grid: max_nm - min_nm ({}) must be a whole number of steps of {} nm",
                                        Num(max_nm - min_nm), Num(step_nm)));
  }
  if (n_intervals > 1e6) throw InputError(where, "wavelength grid: more than a million samples");
  WavelengthGrid g;
  g.kind_ = Kind::kUniform;
  g.step_nm_ = step_nm;
  const size_t n = static_cast<size_t>(n_intervals) + 1;
  g.wavelength_nm_.resize(n);
  // Each sample from its index (no accumulated rounding); the last one is max_nm exactly.
  for (size_t i = 0; i < n; ++i) g.wavelength_nm_[i] = min_nm + static_cast<double>(i) * step_nm;
  g.wavelength_nm_.back() = max_nm;
  if (n == 1) {
    g.bin_lo_nm_ = {min_nm - 0.5 * step_nm};
    g.bin_hi_nm_ = {min_nm + 0.5 * step_nm};
  } else {
    g.SetMidpointBins();
  }
  return g;
}

WavelengthGrid WavelengthGrid::List(std::vector<double> wavelengths_nm, const FileLoc& where) {
  if (wavelengths_nm.size() < 2) {
    throw InputError(where, fmt::format("wavelength list: needs at least 2 wavelengths, got {}", wavelengths_nm.size()));
  }
  for (size_t i = 0; i < wavelengths_nm.size(); ++i) {
    const double w = wavelengths_nm[i];
    if (!std::isfinite(w) || !(w > 0.0)) {
      throw InputError(where, fmt::format("wavelength list: entry {} must be a positive number of nm, got {}", i + 1, Num(w)));
    }
    if (i > 0 && !(w > wavelengths_nm[i - 1])) {
      throw InputError(where, fmt::format("wavelength list: must be strictly increasing, but entry {} ({}) follows {}",
                                          i + 1, Num(w), Num(wavelengths_nm[i - 1])));
    }
  }
  WavelengthGrid g;
  g.kind_ = Kind::kList;
  g.wavelength_nm_ = std::move(wavelengths_nm);
  g.SetMidpointBins();
  return g;
}

WavelengthGrid WavelengthGrid::Rgb() {
  WavelengthGrid g;
  g.kind_ = Kind::kRgb;
  // Red, green, blue: Hillaire 2016 (§2.1,
  // "red (680nm), green (550nm) and blue (440nm)"), Bruneton & Neyret 2008 §2.1 (680, 550, 440 nm).
  g.wavelength_nm_ = {680.0, 550.0, 440.0};
  for (double w : g.wavelength_nm_) {
    g.bin_lo_nm_.push_back(w - 0.5 * kRgbBinWidthNm);
    g.bin_hi_nm_.push_back(w + 0.5 * kRgbBinWidthNm);
  }
  return g;
}

void WavelengthGrid::SetMidpointBins() {
  const std::vector<double>& w = wavelength_nm_;
  const size_t n = w.size();
  SKYBAKE_CHECK_GE(n, size_t{2});
  bin_lo_nm_.resize(n);
  bin_hi_nm_.resize(n);
  bin_lo_nm_[0] = w[0] - 0.5 * (w[1] - w[0]);
  for (size_t i = 1; i < n; ++i) {
    const double mid = 0.5 * (w[i - 1] + w[i]);
    bin_hi_nm_[i - 1] = mid;
    bin_lo_nm_[i] = mid;
  }
  bin_hi_nm_[n - 1] = w[n - 1] + 0.5 * (w[n - 1] - w[n - 2]);
}

double WavelengthGrid::covered_lo_nm() const { return *std::min_element(bin_lo_nm_.begin(), bin_lo_nm_.end()); }
double WavelengthGrid::covered_hi_nm() const { return *std::max_element(bin_hi_nm_.begin(), bin_hi_nm_.end()); }

std::string WavelengthGrid::Describe() const {
  switch (kind_) {
    case Kind::kUniform:
      return fmt::format("uniform {}-{} nm, step {} nm ({} samples; bin i = [lambda_i - step/2, lambda_i + step/2])",
                         Num(wavelength_nm_.front()), Num(wavelength_nm_.back()), Num(step_nm_), size());
    case Kind::kList: {
      std::string s = fmt::format("list of {} wavelengths", size());
      for (size_t i = 0; i < size(); ++i) s += (i == 0 ? " " : ", ") + Num(wavelength_nm_[i]);
      return s + " nm (bins between midpoints)";
    }
    case Kind::kRgb:
      return "RGB 680, 550, 440 nm (R, G, B; not a quadrature)";
  }
  return "";
}

}  // namespace skybake
