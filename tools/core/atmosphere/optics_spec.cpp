#include "atmosphere/optics_spec.h"

#include <fmt/format.h>

namespace skybake {

namespace {

// Coefficients up to 10 m^-1 (an optical depth of 10 per metre: denser than any fog, whose
// extinction is at most ~0.1 m^-1 at 30 m visibility, Koschmieder 3.912 / V).
constexpr double kMaxCoefficientPerM = 10.0;

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::optional<std::array<double, 3>> Rgb(YamlNode node, const NumberSpec& element) {
  std::optional<std::vector<double>> v = node.ToNumberList(element);
  if (!v) return std::nullopt;
  if (v->size() != 3) {
    node.Error(fmt::format("expected 3 values (R, G, B at 680, 550, 440 nm), got {}", v->size()));
    return std::nullopt;
  }
  return std::array<double, 3>{(*v)[0], (*v)[1], (*v)[2]};
}

void EmitRgb(YAML::Emitter& out, const std::array<double, 3>& v, double scale) {
  out << YAML::Flow << YAML::BeginSeq;
  for (double x : v) out << FormatExact(x * scale);
  out << YAML::EndSeq;
}

}  // namespace

std::optional<SpectralTableRef> ParseSpectralTable(YamlMap m) {
  SpectralTableRef t;
  std::optional<std::filesystem::path> file = m.Path("file");
  t.wavelength_column = m.String("wavelength_column", "a column name such as wavelength_nm");
  t.value_column = m.String("value_column", "a column name");
  if (std::optional<YamlMap> where = m.OptionalMap("where")) {
    YAML::Node raw = where->node().raw();
    if (raw.size() != 1) {
      where->node().Error("expected exactly one 'column: value' pair");
    } else {
      auto it = raw.begin();
      std::string col = it->first.Scalar();
      t.where = std::make_pair(col, where->String(col, "a cell value"));
    }
    where->Finish();
  }
  m.Finish();
  if (!file) return std::nullopt;
  t.file = *file;
  return t;
}

void EmitSpectralTable(YAML::Emitter& out, const SpectralTableRef& t, const std::filesystem::path& dir) {
  out << YAML::BeginMap;
  out << YAML::Key << "file" << YAML::Value << t.file.lexically_relative(dir).generic_string();
  out << YAML::Key << "wavelength_column" << YAML::Value << t.wavelength_column;
  out << YAML::Key << "value_column" << YAML::Value << t.value_column;
  if (t.where) {
    out << YAML::Key << "where" << YAML::Value << YAML::BeginMap << YAML::Key << t.where->first << YAML::Value
        << t.where->second << YAML::EndMap;
  }
  out << YAML::EndMap;
}

std::optional<CoefficientSpectrum> ParseCoefficientSpectrum(YamlNode node) {
  YamlMap m = node.ToMap("a coefficient spectrum: {per_m: ...}, {per_km: ...}, {rgb_per_m: [R, G, B]}, "
                         "{rgb_per_km: [...]} or {table: {...}}");
  if (!m.valid()) return std::nullopt;
  CoefficientSpectrum c;
  c.where = node.loc();
  const std::string kind = m.ExactlyOneOf({"per_m", "per_km", "rgb_per_m", "rgb_per_km", "table"});
  bool ok = !kind.empty();
  if (kind == "per_m" || kind == "per_km") {
    const double scale = kind == "per_m" ? 1.0 : 1e-3;
    const std::string unit = kind == "per_m" ? "m^-1" : "km^-1";
    std::optional<double> v = m.OptionalNumber(kind, NumberSpec::Range(0.0, kMaxCoefficientPerM / scale, unit));
    ok = v.has_value();
    c.kind = CoefficientSpectrum::Kind::kPowerLaw;
    c.value_per_m = v.value_or(0.0) * scale;
    c.exponent = m.NumberOr("power_law_exponent", NumberSpec::Range(-10.0, 10.0, "(lambda / reference)^-k"), 0.0);
    std::optional<double> ref = m.OptionalNumber("reference_wavelength_nm", NumberSpec::Range(100.0, 10000.0, "nm"));
    if (ref) {
      c.reference_wavelength_nm = *ref;
    } else if (c.exponent != 0.0) {
      m.ErrorMissing("reference_wavelength_nm", "the wavelength (nm) where the power law equals the coefficient");
      ok = false;
    }
  } else if (kind == "rgb_per_m" || kind == "rgb_per_km") {
    const double scale = kind == "rgb_per_m" ? 1.0 : 1e-3;
    std::optional<YamlNode> v = m.Get(kind);
    std::optional<std::array<double, 3>> rgb =
        Rgb(*v, NumberSpec::Range(0.0, kMaxCoefficientPerM / scale, scale == 1.0 ? "m^-1" : "km^-1"));
    ok = rgb.has_value();
    c.kind = CoefficientSpectrum::Kind::kRgb;
    if (rgb) {
      for (size_t i = 0; i < 3; ++i) c.rgb_per_m[i] = (*rgb)[i] * scale;
    }
  } else if (kind == "table") {
    c.kind = CoefficientSpectrum::Kind::kTable;
    std::optional<YamlNode> t = m.Get("table");
    std::optional<SpectralTableRef> ref = ParseSpectralTable(t->ToMap("{file, wavelength_column, value_column}"));
    ok = ref.has_value();
    if (ref) {
      c.table = *ref;
      if (EndsWith(ref->value_column, "_per_m")) {
        c.table_unit_per_m = 1.0;
      } else if (EndsWith(ref->value_column, "_per_km")) {
        c.table_unit_per_m = 1e-3;
      } else {
        t->Error("value_column '" + ref->value_column + "' must name its unit: end it with _per_m or _per_km");
        ok = false;
      }
    }
  }
  m.Finish();
  if (!ok) return std::nullopt;
  return c;
}

std::optional<AlbedoSpectrum> ParseAlbedoSpectrum(YamlNode node) {
  AlbedoSpectrum a;
  a.where = node.loc();
  const NumberSpec unit_interval = NumberSpec::Range(0.0, 1.0, "");
  if (node.IsScalar()) {
    std::optional<double> v = node.ToNumber(unit_interval);
    if (!v) return std::nullopt;
    a.kind = AlbedoSpectrum::Kind::kConstant;
    a.value = *v;
    return a;
  }
  YamlMap m = node.ToMap("a number from 0 to 1, {rgb: [R, G, B]} or {table: {...}}");
  if (!m.valid()) return std::nullopt;
  const std::string kind = m.ExactlyOneOf({"rgb", "table"});
  bool ok = !kind.empty();
  if (kind == "rgb") {
    std::optional<std::array<double, 3>> rgb = Rgb(*m.Get("rgb"), unit_interval);
    ok = rgb.has_value();
    a.kind = AlbedoSpectrum::Kind::kRgb;
    if (rgb) a.rgb = *rgb;
  } else if (kind == "table") {
    std::optional<SpectralTableRef> ref = ParseSpectralTable(m.Map("table"));
    ok = ref.has_value();
    a.kind = AlbedoSpectrum::Kind::kTable;
    if (ref) a.table = *ref;
  }
  m.Finish();
  if (!ok) return std::nullopt;
  return a;
}

std::optional<PhaseSpec> ParsePhaseSpec(YamlNode node) {
  YamlMap m = node.ToMap("{henyey_greenstein: {g: ...}}, {cornette_shanks: {g: ...}} or {table: {...}}");
  if (!m.valid()) return std::nullopt;
  PhaseSpec p;
  p.where = node.loc();
  const std::string kind = m.ExactlyOneOf({"henyey_greenstein", "cornette_shanks", "table"});
  bool ok = !kind.empty();
  if (kind == "henyey_greenstein" || kind == "cornette_shanks") {
    p.kind = kind == "henyey_greenstein" ? PhaseSpec::Kind::kHenyeyGreenstein : PhaseSpec::Kind::kCornetteShanks;
    YamlMap lobe = m.Map(kind);
    // |g| = 1 is a delta function, which neither model can sample or tabulate.
    NumberSpec open = NumberSpec::Range(-1.0, 1.0, "");
    open.min_inclusive = open.max_inclusive = false;
    open.description = "an asymmetry parameter strictly between -1 and 1";
    std::optional<double> g = lobe.OptionalNumber("g", open);
    if (!g && lobe.valid() && !lobe.Has("g")) lobe.ErrorMissing("g", open.description);
    ok = ok && g.has_value();
    p.g = g.value_or(0.0);
    lobe.Finish();
  } else if (kind == "table") {
    p.kind = PhaseSpec::Kind::kTable;
    YamlMap t = m.Map("table");
    std::optional<std::filesystem::path> file = t.Path("file");
    p.angle_column = t.String("angle_column", "a column name such as angle_deg (or angle_rad)");
    p.value_column = t.String("value_column", "a column name such as phase_per_sr");
    if (!p.angle_column.empty() && !EndsWith(p.angle_column, "_deg") && !EndsWith(p.angle_column, "_rad")) {
      t.node().Error("angle_column '" + p.angle_column + "' must name its unit: end it with _deg or _rad");
      ok = false;
    }
    t.Finish();
    ok = ok && file.has_value();
    if (file) p.file = *file;
  }
  m.Finish();
  if (!ok) return std::nullopt;
  return p;
}

void EmitCoefficientSpectrum(YAML::Emitter& out, const CoefficientSpectrum& c, const std::filesystem::path& dir) {
  out << YAML::BeginMap;
  switch (c.kind) {
    case CoefficientSpectrum::Kind::kPowerLaw:
      out << YAML::Key << "per_m" << YAML::Value << FormatExact(c.value_per_m);
      if (c.exponent != 0.0) {
        out << YAML::Key << "reference_wavelength_nm" << YAML::Value << FormatExact(c.reference_wavelength_nm);
        out << YAML::Key << "power_law_exponent" << YAML::Value << FormatExact(c.exponent);
      }
      break;
    case CoefficientSpectrum::Kind::kRgb:
      out << YAML::Key << "rgb_per_m" << YAML::Value;
      EmitRgb(out, c.rgb_per_m, 1.0);
      break;
    case CoefficientSpectrum::Kind::kTable:
      out << YAML::Key << "table" << YAML::Value;
      EmitSpectralTable(out, c.table, dir);
      break;
  }
  out << YAML::EndMap;
}

void EmitAlbedoSpectrum(YAML::Emitter& out, const AlbedoSpectrum& a, const std::filesystem::path& dir) {
  switch (a.kind) {
    case AlbedoSpectrum::Kind::kConstant: out << FormatExact(a.value); break;
    case AlbedoSpectrum::Kind::kRgb:
      out << YAML::BeginMap << YAML::Key << "rgb" << YAML::Value;
      EmitRgb(out, a.rgb, 1.0);
      out << YAML::EndMap;
      break;
    case AlbedoSpectrum::Kind::kTable:
      out << YAML::BeginMap << YAML::Key << "table" << YAML::Value;
      EmitSpectralTable(out, a.table, dir);
      out << YAML::EndMap;
      break;
  }
}

void EmitPhaseSpec(YAML::Emitter& out, const PhaseSpec& p, const std::filesystem::path& dir) {
  out << YAML::BeginMap;
  if (p.kind == PhaseSpec::Kind::kTable) {
    out << YAML::Key << "table" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "file" << YAML::Value << p.file.lexically_relative(dir).generic_string();
    out << YAML::Key << "angle_column" << YAML::Value << p.angle_column;
    out << YAML::Key << "value_column" << YAML::Value << p.value_column;
    out << YAML::EndMap;
  } else {
    out << YAML::Key << (p.kind == PhaseSpec::Kind::kHenyeyGreenstein ? "henyey_greenstein" : "cornette_shanks")
        << YAML::Value << YAML::BeginMap << YAML::Key << "g" << YAML::Value << FormatExact(p.g) << YAML::EndMap;
  }
  out << YAML::EndMap;
}

}  // namespace skybake
