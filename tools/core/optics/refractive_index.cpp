#include "optics/refractive_index.h"

#include <fmt/format.h>

#include <cmath>

#include "io/csv.h"

namespace skybake::mie {

// Valid refractive indices m = n + ik of aerosol material (docs/mie.md, "Valid ranges"): n from 1
// (the medium itself) to 3 (hematite, the highest of common aerosol minerals: n ~ 3.0 in the
// visible, Sokolik & Toon 1999), k from 0 to 3 (soot has k ~ 0.44-0.47, OPAC).
constexpr double kMinN = 1.0, kMaxN = 3.0, kMaxK = 3.0;

RefractiveIndex ParseRefractiveIndex(const YamlNode& node) {
  RefractiveIndex ri;
  ri.loc = node.loc();
  YamlMap m = node.ToMap("a refractive index ({table: FILE, ...} or {n: N, k: K})");
  if (!m.valid()) return ri;
  const std::string which = m.ExactlyOneOf({"table", "n"});
  if (which == "table") {
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
  return {n_table.Eval(wavelength_nm), k_table.Eval(wavelength_nm)};
}

bool RefractiveIndex::Covers(double min_nm, double max_nm) const {
  if (kind == Kind::kConstant) return true;
  SKYBAKE_CHECK(loaded);
  return n_table.Covers(min_nm, max_nm);
}

std::string RefractiveIndex::RangeText() const {
  if (kind == Kind::kConstant) return "a constant";
  return fmt::format("wavelengths {}-{} nm of {}", FormatExact(n_table.x_min()), FormatExact(n_table.x_max()),
                     file.string());
}

std::string RefractiveIndex::Describe() const {
  if (kind == Kind::kConstant) return "constant " + FormatExact(constant_n) + " + " + FormatExact(constant_k) + "i";
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
  std::string k = "table " + file.string();
  for (const auto& [c, v] : select) k += " " + c + "=" + v;
  return k + " " + wavelength_column + " " + n_column + " " + k_column;
}

void EmitRefractiveIndex(YAML::Emitter& out, const RefractiveIndex& ri, const std::filesystem::path& dir) {
  out << YAML::BeginMap;
  if (ri.kind == RefractiveIndex::Kind::kConstant) {
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
