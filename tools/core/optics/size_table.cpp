#include "optics/size_table.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/csv.h"
#include "io/interp.h"

namespace skybake::mie {

namespace {

// Radii of a table (docs/mie.md, "Valid ranges"): the same 1e-4 - 100 um as a mode's radii.
constexpr double kMinRadiusUm = 1e-4, kMaxRadiusUm = 100.0;

// int_0^1 t e^{a t} dt: the series sum_j a^j / (j! (j + 2)) for |a| < 0.5 (the closed form
// (e^a (a - 1) + 1) / a^2 cancels there), the closed form above.
double TExpMoment(double a) {
  if (std::abs(a) >= 0.5) return (std::exp(a) * (a - 1.0) + 1.0) / (a * a);
  double term = 1.0, sum = 0.0;
  for (int j = 0; j < 30; ++j) {
    sum += term / (j + 2);
    term *= a / (j + 1);
  }
  return sum;
}

}  // namespace

double LinearTimesExpIntegral(double u0, double u1, double f0, double f1, double c) {
  const double h = u1 - u0, a = c * h;
  const double e0 = a == 0.0 ? 1.0 : std::expm1(a) / a;  // int_0^1 e^{a t} dt
  return h * std::exp(c * u0) * (f0 * e0 + (f1 - f0) * TExpMoment(a));
}

void SizeTable::Load() {
  const CsvTable csv = CsvTable::Load(file);
  source = csv.source();
  Diagnostics diags;
  std::vector<std::string> density_columns;
  for (const std::string& c : csv.columns()) {
    if (c.rfind("dV_dlnr_", 0) == 0 || c.rfind("dN_dlnr_", 0) == 0) density_columns.push_back(c);
  }
  if (density_columns.size() != 1) {
    throw InputError(csv.LocOfHeader(),
                     fmt::format("expected exactly one density column, dV_dlnr_<unit> (volume basis) or "
                                 "dN_dlnr_<unit> (number basis), e.g. dV_dlnr_um3_um2; found {} (columns: {})",
                                 density_columns.size(), fmt::join(csv.columns(), ", ")));
  }
  density_column = density_columns[0];
  if (density_column.size() <= 8) {
    throw InputError(csv.LocOfHeader(), fmt::format("column '{}': name its unit after dV_dlnr_ or dN_dlnr_, "
                                                    "e.g. dV_dlnr_um3_um2",
                                                    density_column));
  }
  basis = density_column[1] == 'V' ? SizeBasis::kVolume : SizeBasis::kNumber;
  std::optional<CsvTable::SiColumn> radius = csv.ColumnIn("radius", Quantity::kLength, diags);
  std::vector<double> d = csv.Numbers(density_column, diags);
  diags.ThrowIfAny();
  if (csv.rows() < 2) {
    throw InputError(csv.LocOfHeader(), fmt::format("a size table needs at least 2 rows, got {}", csv.rows()));
  }
  const int rc = csv.ColumnIndex(radius->name), dc = csv.ColumnIndex(density_column);
  bool any_positive = false;
  for (size_t r = 0; r < csv.rows(); ++r) {
    const double r_um = radius->values[r] * 1e6;
    if (!(r_um >= kMinRadiusUm && r_um <= kMaxRadiusUm)) {
      diags.Add(csv.LocOfRow(r), fmt::format("column '{}': radius must be from 1e-4 to 100 um, got {}",
                                             radius->name, csv.cell(r, rc)));
    } else if (r > 0 && !(radius->values[r] > radius->values[r - 1])) {
      diags.Add(csv.LocOfRow(r), fmt::format("column '{}': radii must increase strictly ({} after {})",
                                             radius->name, csv.cell(r, rc), csv.cell(r - 1, rc)));
    }
    if (!(d[r] >= 0.0) || !std::isfinite(d[r])) {
      diags.Add(csv.LocOfRow(r),
                fmt::format("column '{}': a density must be a finite number >= 0, got {}{}", density_column,
                            csv.cell(r, dc), d[r] == -999.0 ? " (AERONET's fill value: a missing retrieval)" : ""));
    }
    any_positive = any_positive || d[r] > 0.0;
  }
  diags.ThrowIfAny();
  if (!any_positive) {
    throw InputError(csv.LocOfHeader(), fmt::format("column '{}': every density is 0", density_column));
  }
  ln_r_um.clear();
  for (double v : radius->values) ln_r_um.push_back(std::log(v * 1e6));
  density = d;
}

double SizeTable::r_min_um() const { return std::exp(ln_r_um.front()); }
double SizeTable::r_max_um() const { return std::exp(ln_r_um.back()); }

double SizeTable::NumberDensity(double u) const {
  SKYBAKE_CHECK(loaded());
  // Outside the table: 0; within 1e-12 of an end (the quadrature's panel ends, rounded through
  // ln(1 um / 1 m)): the end value.
  const double tol = 1e-12 * std::max(1.0, std::abs(u));
  if (u < ln_r_um.front() - tol || u > ln_r_um.back() + tol) return 0.0;
  const size_t i = FindInterval(ln_r_um, u);
  const double t = std::clamp((u - ln_r_um[i]) / (ln_r_um[i + 1] - ln_r_um[i]), 0.0, 1.0);
  const double f = density[i] + (density[i + 1] - density[i]) * t;
  if (basis == SizeBasis::kNumber) return f;
  return f / (4.0 / 3.0 * std::numbers::pi * std::exp(3.0 * u));
}

double SizeTable::NumberMoment(int k) const {
  SKYBAKE_CHECK(loaded());
  // Volume basis: n = V e^{-3u} / (4/3 pi), so n e^{ku} = V e^{(k-3)u} / (4/3 pi).
  const double c = basis == SizeBasis::kNumber ? k : k - 3.0;
  const double scale = basis == SizeBasis::kNumber ? 1.0 : 1.0 / (4.0 / 3.0 * std::numbers::pi);
  double sum = 0.0;
  for (size_t i = 0; i + 1 < ln_r_um.size(); ++i) {
    sum += LinearTimesExpIntegral(ln_r_um[i], ln_r_um[i + 1], density[i], density[i + 1], c);
  }
  return scale * sum;
}

double SizeTable::MeanVolumeUm3() const { return 4.0 / 3.0 * std::numbers::pi * MomentUm(3); }

}  // namespace skybake::mie
