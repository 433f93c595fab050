#include "atmosphere/profile.h"

#include <cmath>

#include <fmt/format.h>

namespace skybake {

std::string ProfileKind(const ProfileSpec& spec) {
  struct V {
    std::string operator()(const Ussa1976Profile&) const { return "ussa1976"; }
    std::string operator()(const ExponentialProfile&) const { return "exponential"; }
    std::string operator()(const TentProfile&) const { return "tent"; }
    std::string operator()(const TableProfile&) const { return "table"; }
  };
  return std::visit(V{}, spec);
}

std::optional<ProfileSpec> ParseProfile(YamlNode node, const std::vector<std::string>& allowed, bool air) {
  std::string expected = "a mapping with one of";
  for (const auto& a : allowed) expected += " '" + a + "'";
  // "profile: ussa1976" is accepted as a shorthand for {ussa1976: {}}.
  if (node.IsScalar()) {
    std::optional<std::string> kind = node.ToChoice(allowed);
    if (!kind) return std::nullopt;
    if (*kind == "ussa1976") return Ussa1976Profile{};
    node.Error("'" + *kind + "' needs parameters: write it as a mapping, e.g. {" + *kind + ": {...}}");
    return std::nullopt;
  }
  YamlMap m = node.ToMap(expected);
  if (!m.valid()) return std::nullopt;
  std::string kind;
  {
    std::vector<std::string> present;
    for (const auto& a : allowed) {
      if (m.Has(a)) present.push_back(a);
    }
    if (present.size() != 1) {
      node.Error(present.empty() ? "expected one of the profile kinds " + fmt::format("'{}'", fmt::join(allowed, "', '"))
                                 : "give only one profile kind, got " + fmt::format("'{}'", fmt::join(present, "' and '")));
      m.Finish();
      return std::nullopt;
    }
    kind = present[0];
  }
  std::optional<ProfileSpec> result;
  if (kind == "ussa1976") {
    std::optional<YamlNode> v = m.Get("ussa1976");
    if (v->IsMap()) v->ToMap().Finish();
    else if (!v->IsNull()) v->ErrorExpected("an empty mapping {}");
    result = Ussa1976Profile{};
  } else if (kind == "exponential") {
    YamlMap e = m.Map("exponential");
    ExponentialProfile p;
    p.scale_height_m = e.Number("scale_height_km", NumberSpec::Range(0.1, 1000.0, "km"), 8.0) * 1e3;
    p.base_altitude_m = e.NumberOr("base_altitude_km", NumberSpec::Range(-10.0, 100.0, "km"), 0.0) * 1e3;
    // exp(-(z - base) / H) at the ground must stay a double (e^500 ~ 1e217).
    if (p.base_altitude_m / p.scale_height_m > 500.0) {
      e.node().Error(fmt::format("base_altitude_km / scale_height_km must be at most 500 (got {} km / {} km): the "
                                 "profile would overflow at the ground",
                                 FormatExact(p.base_altitude_m / 1e3), FormatExact(p.scale_height_m / 1e3)));
    }
    e.Finish();
    result = p;
  } else if (kind == "tent") {
    YamlMap t = m.Map("tent");
    TentProfile p;
    p.center_m = t.Number("center_km", NumberSpec::Range(-10.0, 1000.0, "km"), 25.0) * 1e3;
    p.half_width_m = t.Number("half_width_km", NumberSpec::Range(0.01, 1000.0, "km"), 15.0) * 1e3;
    t.Finish();
    result = p;
  } else if (kind == "table") {
    YamlMap t = m.Map("table");
    TableProfile p;
    std::optional<std::filesystem::path> file = t.Path("file");
    p.altitude_column = t.String("altitude_column", "a column name such as altitude_km");
    p.value_column = t.String("value_column", "a column name");
    std::string interp = t.ChoiceOr("interpolation", {"log", "linear"}, "log");
    p.interpolation = interp == "linear" ? Interpolation::kLinear : Interpolation::kLogLinear;
    std::string outside = t.ChoiceOr("outside", {"error", "zero"}, "error");
    p.zero_outside = outside == "zero";
    if (air) {
      // Air needs its temperature (ozone cross-sections, the isothermal fits) and an absolute density.
      p.temperature_column = t.String("temperature_column", "a column name such as temperature_K");
      if (p.zero_outside) t.node().Error("an air table must cover the whole atmosphere: 'outside: zero' is not allowed");
    }
    t.Finish();
    if (file) {
      p.file = *file;
      result = p;
    }
  }
  m.Finish();
  return result;
}

void EmitProfile(YAML::Emitter& out, const ProfileSpec& spec, const std::filesystem::path& base_dir) {
  out << YAML::BeginMap;
  if (std::holds_alternative<Ussa1976Profile>(spec)) {
    out << YAML::Key << "ussa1976" << YAML::Value << YAML::BeginMap << YAML::EndMap;
  } else if (const auto* e = std::get_if<ExponentialProfile>(&spec)) {
    out << YAML::Key << "exponential" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "scale_height_km" << YAML::Value << FormatExact(e->scale_height_m / 1e3);
    out << YAML::Key << "base_altitude_km" << YAML::Value << FormatExact(e->base_altitude_m / 1e3);
    out << YAML::EndMap;
  } else if (const auto* t = std::get_if<TentProfile>(&spec)) {
    out << YAML::Key << "tent" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "center_km" << YAML::Value << FormatExact(t->center_m / 1e3);
    out << YAML::Key << "half_width_km" << YAML::Value << FormatExact(t->half_width_m / 1e3);
    out << YAML::EndMap;
  } else if (const auto* tb = std::get_if<TableProfile>(&spec)) {
    out << YAML::Key << "table" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "file" << YAML::Value
        << std::filesystem::path(tb->file).lexically_relative(base_dir).generic_string();
    out << YAML::Key << "altitude_column" << YAML::Value << tb->altitude_column;
    out << YAML::Key << "value_column" << YAML::Value << tb->value_column;
    out << YAML::Key << "interpolation" << YAML::Value
        << (tb->interpolation == Interpolation::kLinear ? "linear" : "log");
    out << YAML::Key << "outside" << YAML::Value << (tb->zero_outside ? "zero" : "error");
    if (!tb->temperature_column.empty()) out << YAML::Key << "temperature_column" << YAML::Value << tb->temperature_column;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
}

LoadedTable LoadProfileTable(const TableProfile& spec) {
  CsvTable csv = CsvTable::Load(spec.file);
  Diagnostics diags;
  std::optional<CsvTable::SiColumn> alt = csv.NamedColumnIn(spec.altitude_column, Quantity::kLength, diags);
  std::vector<double> values = csv.Numbers(spec.value_column, diags);
  if (alt && values.size() == alt->values.size()) {
    for (size_t r = 0; r < csv.rows(); ++r) {
      if (r > 0 && !(alt->values[r] > alt->values[r - 1]) && std::isfinite(alt->values[r]) &&
          std::isfinite(alt->values[r - 1])) {
        diags.Add(csv.LocOfRow(r), fmt::format("column '{}': altitudes must increase strictly ({} after {})",
                                               spec.altitude_column, csv.cell(r, csv.ColumnIndex(spec.altitude_column)),
                                               csv.cell(r - 1, csv.ColumnIndex(spec.altitude_column))));
      }
      if (std::isfinite(values[r]) && values[r] < 0.0) {
        diags.Add(csv.LocOfRow(r), fmt::format("column '{}': a density cannot be negative, got {}",
                                               spec.value_column, csv.cell(r, csv.ColumnIndex(spec.value_column))));
      }
    }
  }
  diags.ThrowIfAny();
  return LoadedTable{Interpolant1D(alt->values, values, spec.interpolation), csv.source(), spec.value_column};
}

std::vector<double> SampleShape(const ProfileSpec& spec, const std::vector<double>& z,
                                const LoadedTable* table) {
  std::vector<double> out(z.size(), 0.0);
  if (const auto* e = std::get_if<ExponentialProfile>(&spec)) {
    for (size_t i = 0; i < z.size(); ++i) out[i] = std::exp(-(z[i] - e->base_altitude_m) / e->scale_height_m);
  } else if (const auto* t = std::get_if<TentProfile>(&spec)) {
    for (size_t i = 0; i < z.size(); ++i) out[i] = std::max(0.0, 1.0 - std::abs(z[i] - t->center_m) / t->half_width_m);
  } else if (const auto* tb = std::get_if<TableProfile>(&spec)) {
    SKYBAKE_CHECK(table != nullptr);
    const Interpolant1D& f = table->values;
    if (!tb->zero_outside && !f.Covers(z.front(), z.back())) {
      throw InputError(FileLoc{tb->file.string(), 0},
                       fmt::format("the table covers altitudes {:g} to {:g} km but the atmosphere needs {:g} to {:g} km "
                                   "(extend the table or set 'outside: zero')",
                                   f.x_min() / 1e3, f.x_max() / 1e3, z.front() / 1e3, z.back() / 1e3));
    }
    for (size_t i = 0; i < z.size(); ++i) out[i] = f.Covers(z[i], z[i]) ? f.Eval(z[i]) : 0.0;
  } else {
    SKYBAKE_CHECK(!"SampleShape does not handle ussa1976");
  }
  return out;
}

}  // namespace skybake
