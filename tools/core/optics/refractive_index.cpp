#include "optics/refractive_index.h"

#include <fmt/format.h>

#include <cmath>

#include "io/csv.h"

namespace skybake::mie {

// Valid refractive indices m = n + ik of aerosol material (docs/mie.md, "Valid ranges"): n from 1
// (the medium itself) to 3 (hematite, the highest of common aerosol minerals: n ~ 3.0 in the
// visible, Sokolik & Toon 1999), k from 0 to 3 (soot has k ~ 0.44-0.47, OPAC).
constexpr double kMinN = 1.0, kMaxN = 3.0, kMaxK = 3.0;
// Wavelengths of points: the range of `mie-tables build`'s grid options.
constexpr double kMinPointNm = 200.0, kMaxPointNm = 3000.0;

namespace {

// `points: {wavelength_nm: [...], n: [...], k: [...]}` and `extrapolation:` into ri.
void ParsePoints(YamlMap& m, RefractiveIndex& ri) {
  YamlMap p = m.Map("points");
  if (!p.valid()) return;
  const std::vector<double> wl = p.NumberList("wavelength_nm", NumberSpec::Range(kMinPointNm, kMaxPointNm, "nm"));
  const std::vector<double> n = p.NumberList("n", NumberSpec::Range(kMinN, kMaxN, ""));
  const std::vector<double> k = p.NumberList("k", NumberSpec::Range(0.0, kMaxK, ""));
  const std::string rule = m.Choice("extrapolation", {"nearest", "linear"});
  ri.extrapolation = rule == "linear" ? RefractiveIndex::Extrapolation::kLinear : RefractiveIndex::Extrapolation::kNearest;
  bool ok = !wl.empty() && wl.size() == n.size() && wl.size() == k.size();
  if (!wl.empty() && (wl.size() != n.size() || wl.size() != k.size())) {
    p.node().Error(fmt::format("wavelength_nm, n and k must have the same length ({}, {}, {})", wl.size(), n.size(),
                               k.size()));
  }
  for (size_t i = 1; ok && i < wl.size(); ++i) {
    if (!(wl[i] > wl[i - 1])) {
      p.Get("wavelength_nm")->Error(fmt::format("wavelengths must increase strictly ({} after {})",
                                                FormatExact(wl[i]), FormatExact(wl[i - 1])));
      ok = false;
    }
  }
  if (ok && ri.extrapolation == RefractiveIndex::Extrapolation::kLinear && wl.size() < 2) {
    p.Get("wavelength_nm")->Error("linear extrapolation needs at least 2 points");
    ok = false;
  }
  p.Finish();
  if (!ok) return;
  ri.n_table = Interpolant1D(wl, n, Interpolation::kLinear);
  ri.k_table = Interpolant1D(wl, k, Interpolation::kLogLinear);
  ri.loaded = true;
}

// The end interval of `t` continued to x (t has >= 2 points): linear, or log-linear where both
// ends are positive and the table is log-linear; clamped at 0.
double ExtendEndInterval(const Interpolant1D& t, double x) {
  const std::vector<double>& xs = t.x();
  const std::vector<double>& ys = t.y();
  const size_t i = x < xs.front() ? 0 : xs.size() - 2;
  const double s = (x - xs[i]) / (xs[i + 1] - xs[i]);
  if (t.mode() == Interpolation::kLogLinear && ys[i] > 0.0 && ys[i + 1] > 0.0) {
    return std::exp(std::log(ys[i]) + s * (std::log(ys[i + 1]) - std::log(ys[i])));
  }
  return std::max(0.0, ys[i] + s * (ys[i + 1] - ys[i]));
}

}  // namespace

RefractiveIndex ParseRefractiveIndex(const YamlNode& node) {
  RefractiveIndex ri;
  ri.loc = node.loc();
  YamlMap m = node.ToMap("a refractive index ({table: FILE, ...} or {n: N, k: K})");
  if (!m.valid()) return ri;
  const std::string which = m.ExactlyOneOf({"table", "points", "n"});
  if (which == "points") {
    ri.kind = RefractiveIndex::Kind::kPoints;
    ParsePoints(m, ri);
  } else if (which == "table") {
    ri.kind = RefractiveIndex::Kind::kTable;
    if (std::optional<std::filesystem::path> p = m.Path("table")) ri.file = *p;
    if (std::optional<YamlMap> sel = m.OptionalMap("select")) {
      for (auto it = sel->node().raw().begin(); sel->valid() && it != sel->node().raw().end(); ++it) {
        if (!it->first.IsScalar()) continue;  // reported by Finish
        const std::string column = it->first.Scalar();
        ri.select.emplace_back(column, sel->String(column, "a cell value to match"));
      }
      sel->Finish();
    }
    ri.wavelength_column = m.OptionalString("wavelength_column", "a column name").value_or("");
    ri.n_column = m.OptionalString("n_column", "a column name").value_or(ri.n_column);
    ri.k_column = m.OptionalString("k_column", "a column name").value_or(ri.k_column);
  } else if (which == "n") {
    ri.kind = RefractiveIndex::Kind::kConstant;
    ri.constant_n = m.Number("n", NumberSpec::Range(kMinN, kMaxN, ""), 1.0);
    ri.constant_k = m.NumberOr("k", NumberSpec::Range(0.0, kMaxK, ""), 0.0);
  }
  m.Finish();
  return ri;
}

void RefractiveIndex::Load() {
  if (kind != Kind::kTable || loaded) return;
  CsvTable csv = CsvTable::Load(file);
  for (const auto& [column, value] : select) {
    if (csv.ColumnIndex(column) < 0) {
      throw InputError(loc, fmt::format("select: the table {} has no column '{}' (columns: {})", file.string(),
                                        column, fmt::join(csv.columns(), ", ")));
    }
    csv = csv.Filter(column, value);
  }
  if (csv.rows() == 0) {
    std::vector<std::string> conds;
    for (const auto& [column, value] : select) conds.push_back(column + " = '" + value + "'");
    throw InputError(loc, fmt::format("select: no row of {} has {}", file.string(), fmt::join(conds, " and ")));
  }
  Diagnostics diags;
  std::optional<CsvTable::SiColumn> wl =
      wavelength_column.empty() ? csv.ColumnIn("wavelength", Quantity::kWavelength, diags)
                                : csv.NamedColumnIn(wavelength_column, Quantity::kWavelength, diags);
  std::vector<double> n = csv.Numbers(n_column, diags);
  std::vector<double> k = csv.Numbers(k_column, diags);
  if (wl && n.size() == csv.rows() && k.size() == csv.rows()) {
    for (size_t r = 0; r < csv.rows(); ++r) {
      if (r > 0 && std::isfinite(wl->values[r]) && std::isfinite(wl->values[r - 1]) &&
          !(wl->values[r] > wl->values[r - 1])) {
        const int c = csv.ColumnIndex(wl->name);
        diags.Add(csv.LocOfRow(r), fmt::format("column '{}': wavelengths must increase strictly ({} after {})",
                                               wl->name, csv.cell(r, c), csv.cell(r - 1, c)));
      }
      if (std::isfinite(n[r]) && !(n[r] >= kMinN && n[r] <= kMaxN)) {
        diags.Add(csv.LocOfRow(r), fmt::format("column '{}': the real part n must be from 1 to 3, got {}", n_column,
                                               csv.cell(r, csv.ColumnIndex(n_column))));
      }
      if (std::isfinite(k[r]) && !(k[r] >= 0.0 && k[r] <= kMaxK)) {
        diags.Add(csv.LocOfRow(r),
                  fmt::format("column '{}': k must be from 0 to 3 (m = n + ik; absorbing media have k > 0), got {}",
                              k_column, csv.cell(r, csv.ColumnIndex(k_column))));
      }
    }
  }
  diags.ThrowIfAny();
  n_table = Interpolant1D(wl->values, n, Interpolation::kLinear);
  k_table = Interpolant1D(wl->values, k, Interpolation::kLogLinear);
  loaded = true;
}

std::complex<double> RefractiveIndex::At(double wavelength_nm) const {
  if (kind == Kind::kConstant) return {constant_n, constant_k};
  SKYBAKE_CHECK(loaded);
  if (kind == Kind::kPoints && !n_table.Covers(wavelength_nm, wavelength_nm)) {
    if (extrapolation == Extrapolation::kNearest) {
      const size_t end = wavelength_nm < n_table.x_min() ? 0 : n_table.x().size() - 1;
      return {n_table.y()[end], k_table.y()[end]};
    }
    return {ExtendEndInterval(n_table, wavelength_nm), ExtendEndInterval(k_table, wavelength_nm)};
  }
  return {n_table.Eval(wavelength_nm), k_table.Eval(wavelength_nm)};
}

bool RefractiveIndex::Covers(double min_nm, double max_nm) const {
  if (kind == Kind::kConstant) return true;
  SKYBAKE_CHECK(loaded);
  if (kind == Kind::kPoints) {
    // The extension is monotonic on each side, so its extremes are at the grid's ends.
    for (double wl : {min_nm, max_nm}) {
      const std::complex<double> m = At(wl);
      if (!(m.real() >= kMinN && m.real() <= kMaxN && m.imag() >= 0.0 && m.imag() <= kMaxK)) return false;
    }
    return true;
  }
  return n_table.Covers(min_nm, max_nm);
}

std::string RefractiveIndex::RangeText() const {
  if (kind == Kind::kConstant) return "a constant";
  if (kind == Kind::kPoints) {
    return fmt::format("points at {}-{} nm and their linear extrapolation while n stays in 1-3 and k in 0-3",
                       FormatExact(n_table.x_min()), FormatExact(n_table.x_max()));
  }
  return fmt::format("wavelengths {}-{} nm of {}", FormatExact(n_table.x_min()), FormatExact(n_table.x_max()),
                     file.string());
}

namespace {
// "points 440, 675, 870, 1020 nm: n 1.4, ...; k 0.01, ...; nearest outside".
std::string PointsText(const RefractiveIndex& ri) {
  std::vector<std::string> wl, n, k;
  for (size_t i = 0; i < ri.n_table.x().size(); ++i) {
    wl.push_back(FormatExact(ri.n_table.x()[i]));
    n.push_back(FormatExact(ri.n_table.y()[i]));
    k.push_back(FormatExact(ri.k_table.y()[i]));
  }
  return fmt::format("points {} nm: n {}; k {}; {} outside", fmt::join(wl, ", "), fmt::join(n, ", "),
                     fmt::join(k, ", "),
                     ri.extrapolation == RefractiveIndex::Extrapolation::kNearest ? "nearest" : "linear");
}
}  // namespace

std::string RefractiveIndex::Describe() const {
  if (kind == Kind::kConstant) return "constant " + FormatExact(constant_n) + " + " + FormatExact(constant_k) + "i";
  if (kind == Kind::kPoints) return PointsText(*this);
  std::string d = "table " + file.filename().string();
  if (!select.empty()) {
    std::vector<std::string> conds;
    for (const auto& [c, v] : select) conds.push_back(c + " = " + v);
    d += " (" + fmt::format("{}", fmt::join(conds, ", ")) + ")";
  }
  return d;
}

std::string RefractiveIndex::Key() const {
  if (kind == Kind::kConstant) return "constant " + FormatExact(constant_n) + " " + FormatExact(constant_k);
  if (kind == Kind::kPoints) return PointsText(*this);
  std::string k = "table " + file.string();
  for (const auto& [c, v] : select) k += " " + c + "=" + v;
  return k + " " + wavelength_column + " " + n_column + " " + k_column;
}

void EmitRefractiveIndex(YAML::Emitter& out, const RefractiveIndex& ri, const std::filesystem::path& dir) {
  out << YAML::BeginMap;
  if (ri.kind == RefractiveIndex::Kind::kPoints) {
    std::vector<std::string> wl, n, k;
    for (size_t i = 0; i < ri.n_table.x().size(); ++i) {
      wl.push_back(FormatExact(ri.n_table.x()[i]));
      n.push_back(FormatExact(ri.n_table.y()[i]));
      k.push_back(FormatExact(ri.k_table.y()[i]));
    }
    out << YAML::Key << "points" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "wavelength_nm" << YAML::Value << YAML::Flow << wl;
    out << YAML::Key << "n" << YAML::Value << YAML::Flow << n;
    out << YAML::Key << "k" << YAML::Value << YAML::Flow << k;
    out << YAML::EndMap;
    out << YAML::Key << "extrapolation" << YAML::Value
        << (ri.extrapolation == RefractiveIndex::Extrapolation::kNearest ? "nearest" : "linear");
  } else if (ri.kind == RefractiveIndex::Kind::kConstant) {
    out << YAML::Key << "n" << YAML::Value << FormatExact(ri.constant_n);
    out << YAML::Key << "k" << YAML::Value << FormatExact(ri.constant_k);
  } else {
    out << YAML::Key << "table" << YAML::Value << ri.file.lexically_relative(dir).generic_string();
    if (!ri.select.empty()) {
      out << YAML::Key << "select" << YAML::Value << YAML::BeginMap;
      for (const auto& [c, v] : ri.select) out << YAML::Key << c << YAML::Value << YAML::DoubleQuoted << v;
      out << YAML::EndMap;
    }
    if (!ri.wavelength_column.empty()) out << YAML::Key << "wavelength_column" << YAML::Value << ri.wavelength_column;
    out << YAML::Key << "n_column" << YAML::Value << ri.n_column;
    out << YAML::Key << "k_column" << YAML::Value << ri.k_column;
  }
  out << YAML::EndMap;
}

}  // namespace skybake::mie
