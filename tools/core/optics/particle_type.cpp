#include "optics/particle_type.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace skybake::mie {

namespace {

// Phi(b) - Phi(a) for the standard normal, accurate in both tails (erfc of the side away from 0).
double NormalMass(double a, double b) {
  if (a >= 0.0) return 0.5 * (std::erfc(a / std::numbers::sqrt2) - std::erfc(b / std::numbers::sqrt2));
  if (b <= 0.0) return 0.5 * (std::erfc(-b / std::numbers::sqrt2) - std::erfc(-a / std::numbers::sqrt2));
  return 1.0 - 0.5 * (std::erfc(-a / std::numbers::sqrt2) + std::erfc(b / std::numbers::sqrt2));
}

bool IsIdentifier(const std::string& s) {
  if (s.empty() || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

// Ranges of the mode parameters (docs/mie.md, "Valid ranges"): sigma_g in [1.0001, 5] (narrower
// is a single sphere, and the radius quadrature has no panel left; OPAC's widest
// mode, mineral nucleation, has sigma_g = 1.95; 5 keeps the distribution inside 1e-4-100 um), a
// weight in (0, 1e12] (number densities in cm^-3 up to 1e12 or relative values).
NumberSpec SigmaG() {
  NumberSpec s = NumberSpec::Range(1.0001, 5.0, "");
  s.description = "a number from 1.0001 to 5";
  return s;
}
NumberSpec LnSigmaG() {
  NumberSpec s = NumberSpec::Range(1e-4, 1.6094379124341003, "");  // ln 5
  s.description = "a number from 0.0001 to 1.609 (ln 5)";
  return s;
}
NumberSpec Weight() {
  NumberSpec s = NumberSpec::Range(0.0, 1e12, "");
  s.min_inclusive = false;
  s.description = "a positive number up to 1e12";
  return s;
}

constexpr WeightKind kWeightKinds[] = {WeightKind::kNumberDensityCm3, WeightKind::kRelativeNumber,
                                       WeightKind::kVolumeUm3PerCm3, WeightKind::kRelativeVolume};

// The centre, width and truncation of a log-normal mode.
void ParseLogNormalShape(YamlMap& m, SizeMode& mode) {
  // Centre.
  const std::string centre = m.ExactlyOneOf({"median_radius_um", "effective_radius_um"});
  if (centre == "median_radius_um") {
    mode.median_radius_um = m.Number(centre, NumberSpec::Range(1e-4, 100.0, "um"), 1.0);
    const std::string b = m.Choice("basis", {"number", "volume"});
    if (!b.empty()) mode.basis = b == "number" ? SizeBasis::kNumber : SizeBasis::kVolume;
    if (!mode.basis) mode.basis = SizeBasis::kNumber;  // (reported above)
  } else if (centre == "effective_radius_um") {
    mode.effective_radius_um = m.Number(centre, NumberSpec::Range(1e-4, 100.0, "um"), 1.0);
    if (std::optional<YamlNode> b = m.Get("basis")) {
      b->Error("not used with effective_radius_um (r_eff = <r^3>/<r^2> does not depend on the basis); remove it");
    }
  } else {
    m.Known({"basis"});
  }
  // Width.
  const std::string width = m.ExactlyOneOf({"sigma_g", "ln_sigma_g"});
  if (width == "sigma_g") {
    mode.width_is_sigma_g = true;
    mode.width_value = m.Number(width, SigmaG(), 2.0);
  } else if (width == "ln_sigma_g") {
    mode.width_value = m.Number(width, LnSigmaG(), 0.5);
  } else {
    mode.width_value = 0.5;
  }
  // Truncation.
  mode.r_min_um = m.Number("r_min_um", NumberSpec::Range(1e-4, 100.0, "um"), 0.0);
  mode.r_max_um = m.Number("r_max_um", NumberSpec::Range(1e-4, 100.0, "um"), 0.0);
  if (mode.r_min_um > 0.0 && mode.r_max_um > 0.0 && !(mode.r_max_um > mode.r_min_um)) {
    m.Get("r_max_um")->Error(fmt::format("must be greater than r_min_um ({} <= {})", FormatExact(mode.r_max_um),
                                         FormatExact(mode.r_min_um)));
  }
}

// A tabulated mode: the table gives the shape and the radius range; the log-normal keys are errors.
void ParseSizeTableKey(YamlMap& m, const YamlNode& st, SizeMode& mode) {
  SizeTable table;
  table.loc = st.loc();
  if (std::optional<std::filesystem::path> p = m.Path("size_table")) table.file = *p;
  for (const char* key : {"basis", "median_radius_um", "effective_radius_um", "sigma_g", "ln_sigma_g",
                          "r_min_um", "r_max_um"}) {
    if (std::optional<YamlNode> n = m.Get(key)) {
      n->Error(std::string("not used with size_table (the table gives the distribution and its radii); remove ") +
               key);
    }
  }
  mode.table = std::move(table);
}

}  // namespace

const char* WeightKey(WeightKind kind) {
  switch (kind) {
    case WeightKind::kNumberDensityCm3: return "number_density_cm3";
    case WeightKind::kRelativeNumber: return "relative_number";
    case WeightKind::kVolumeUm3PerCm3: return "volume_um3_per_cm3";
    case WeightKind::kRelativeVolume: return "relative_volume";
  }
  return "";
}

bool IsVolumeWeight(WeightKind kind) {
  return kind == WeightKind::kVolumeUm3PerCm3 || kind == WeightKind::kRelativeVolume;
}

// ---------------------------------------------------------------------------- log-normal algebra

double SizeMode::LnSigma() const {
  SKYBAKE_CHECK(!IsTable());
  return width_is_sigma_g ? std::log(width_value) : width_value;
}

double SizeMode::NumberMedianRadiusUm() const {
  const double s2 = LnSigma() * LnSigma();
  if (effective_radius_um) return *effective_radius_um * std::exp(-2.5 * s2);
  SKYBAKE_CHECK(median_radius_um && basis);
  return *basis == SizeBasis::kNumber ? *median_radius_um : *median_radius_um * std::exp(-3.0 * s2);
}

double SizeMode::VolumeMedianRadiusUm() const {
  return NumberMedianRadiusUm() * std::exp(3.0 * LnSigma() * LnSigma());
}
double SizeMode::EffectiveRadiusUm() const {
  return NumberMedianRadiusUm() * std::exp(2.5 * LnSigma() * LnSigma());
}
double SizeMode::EffectiveVariance() const { return std::expm1(LnSigma() * LnSigma()); }
double SizeMode::MeanRadiusUm() const { return NumberMedianRadiusUm() * std::exp(0.5 * LnSigma() * LnSigma()); }

double SizeMode::NumberFractionInside() const {
  if (IsTable()) return 1.0;
  const double s = LnSigma();
  const double mu = std::log(NumberMedianRadiusUm());
  return NormalMass((std::log(r_min_um) - mu) / s, (std::log(r_max_um) - mu) / s);
}

double SizeMode::MomentInsideUm(int k) const {
  if (IsTable()) return table->MomentUm(k);
  const double s = LnSigma();
  const double rg = NumberMedianRadiusUm();
  const double mu = std::log(rg);
  const double a = (std::log(r_min_um) - mu) / s, b = (std::log(r_max_um) - mu) / s;
  return std::pow(rg, k) * std::exp(0.5 * k * k * s * s) * NormalMass(a - k * s, b - k * s) / NormalMass(a, b);
}

double SizeMode::MeanVolumeInsideUm3() const { return 4.0 / 3.0 * std::numbers::pi * MomentInsideUm(3); }

std::vector<double> ParticleType::NumberFractions() const {
  std::vector<double> f;
  double total = 0.0;
  for (const SizeMode& m : modes) {
    const double n = IsVolumeWeight(m.weight_kind) ? m.weight / m.MeanVolumeInsideUm3() : m.weight;
    f.push_back(n);
    total += n;
  }
  for (double& v : f) v /= total;
  return f;
}

double ParticleType::MeanVolumeUm3() const {
  const std::vector<double> f = NumberFractions();
  double v = 0.0;
  for (size_t i = 0; i < modes.size(); ++i) v += f[i] * modes[i].MeanVolumeInsideUm3();
  return v;
}

// ---------------------------------------------------------------------------- loading

ParticleType ParseParticleType(const YamlDocument& doc, const std::string& name) {
  ParticleType type;
  type.name = name;
  type.file = doc.display_name();
  YamlMap root = doc.RootMap();
  std::optional<RefractiveIndex> default_index;
  if (std::optional<YamlNode> ri = root.Get("refractive_index")) default_index = ParseRefractiveIndex(*ri);
  std::vector<YamlNode> modes = root.Seq("modes");
  if (root.Has("modes") && modes.empty() && root.Get("modes")->IsSeq()) {
    root.Get("modes")->Error("expected at least one mode");
  }
  std::set<std::string> names;
  std::optional<std::pair<WeightKind, std::string>> first_weight;  // kind, mode name
  const std::string weight_expected = "a weight: {number_density_cm3: N}, {relative_number: w}, "
                                      "{volume_um3_per_cm3: V} or {relative_volume: w}";
  for (const YamlNode& node : modes) {
    YamlMap m = node.ToMap("a log-normal mode (a mapping)");
    if (!m.valid()) continue;
    SizeMode mode;
    mode.loc = node.loc();
    if (std::optional<YamlNode> n = m.Get("name")) {
      if (std::optional<std::string> s = n->ToString("a lowercase identifier")) {
        if (!IsIdentifier(*s)) {
          n->ErrorExpected("a lowercase identifier (a-z, 0-9, _; starting with a letter)");
        } else if (!names.insert(*s).second) {
          n->Error("mode name '" + *s + "' is used twice");
        }
        mode.name = *s;
      }
    } else {
      m.ErrorMissing("name", "a lowercase identifier");
    }
    // Refractive index: the mode's own or the type's default.
    if (std::optional<YamlNode> ri = m.Get("refractive_index")) {
      mode.index = ParseRefractiveIndex(*ri);
    } else if (default_index) {
      mode.index = *default_index;
    } else {
      m.ErrorMissing("refractive_index", "a refractive index (the type gives no default)");
    }
    if (std::optional<YamlNode> st = m.Get("size_table")) {
      ParseSizeTableKey(m, *st, mode);
    } else {
      ParseLogNormalShape(m, mode);
    }
    // Weight.
    if (std::optional<YamlNode> wnode = m.Get("weight")) {
      YamlMap w = wnode->ToMap(weight_expected);
      if (w.valid()) {
        const std::string key =
            w.ExactlyOneOf({"number_density_cm3", "relative_number", "volume_um3_per_cm3", "relative_volume"});
        for (WeightKind kind : kWeightKinds) {
          if (key != WeightKey(kind)) continue;
          mode.weight_kind = kind;
          mode.weight = w.Number(key, Weight(), 1.0);
          if (!first_weight) {
            first_weight = std::make_pair(kind, mode.name);
          } else if (first_weight->first != kind) {
            wnode->Error(fmt::format("every mode must give its weight with the same key ('{}' in mode '{}', '{}' here)",
                                     WeightKey(first_weight->first), first_weight->second, key));
          }
        }
        w.Finish();
      }
    } else {
      m.ErrorMissing("weight", weight_expected);
    }
    m.Finish();
    type.modes.push_back(std::move(mode));
  }
  root.Finish();
  doc.ThrowIfErrors();

  // Cross-field checks that need the numbers.
  for (const SizeMode& mode : type.modes) {
    if (mode.IsTable()) continue;
    const double z = mode.NumberFractionInside();
    if (!(z >= 1e-12)) {
      doc.diags().Add(mode.loc, fmt::format("mode '{}': [r_min_um, r_max_um] = [{}, {}] holds only {:.3g} of its "
                                            "particles (number median radius {:.6g} um)",
                                            mode.name, FormatExact(mode.r_min_um), FormatExact(mode.r_max_um), z,
                                            mode.NumberMedianRadiusUm()));
    }
  }
  doc.ThrowIfErrors();

  // Size tables (their bounds become the mode's), then refractive-index tables, each distinct
  // one read once.
  type.inputs.push_back(doc.display_name());
  Diagnostics table_errors;
  for (SizeMode& mode : type.modes) {
    if (!mode.IsTable()) continue;
    try {
      mode.table->Load();
    } catch (const InputError& e) {
      for (const Diagnostic& d : e.diagnostics()) table_errors.Add(d.loc, d.message);
      continue;
    }
    mode.r_min_um = mode.table->r_min_um();
    mode.r_max_um = mode.table->r_max_um();
    if (std::find(type.inputs.begin(), type.inputs.end(), mode.table->file) == type.inputs.end()) {
      type.inputs.push_back(mode.table->file);
    }
  }
  table_errors.ThrowIfAny();
  std::map<std::string, RefractiveIndex> loaded;
  for (SizeMode& mode : type.modes) {
    if (mode.index.kind != RefractiveIndex::Kind::kTable) continue;
    const std::string key = mode.index.Key();
    auto it = loaded.find(key);
    if (it == loaded.end()) {
      mode.index.Load();
      loaded.emplace(key, mode.index);
      if (std::find(type.inputs.begin(), type.inputs.end(), mode.index.file) == type.inputs.end()) {
        type.inputs.push_back(mode.index.file);
      }
    } else {
      const FileLoc loc = mode.index.loc;
      mode.index = it->second;
      mode.index.loc = loc;
    }
  }
  return type;
}

ParticleType LoadParticleType(const std::filesystem::path& path) {
  YamlDocument doc = YamlDocument::Load(path);
  ParticleType t = ParseParticleType(doc, path.stem().string());
  t.file = path;
  return t;
}

void CheckWavelengthCoverage(const ParticleType& type, double min_nm, double max_nm) {
  Diagnostics d;
  for (const SizeMode& mode : type.modes) {
    if (!mode.index.Covers(min_nm, max_nm)) {
      d.Add(mode.index.loc,
            fmt::format("mode '{}': the refractive index covers {}, the wavelength grid needs {}-{} nm", mode.name,
                        mode.index.RangeText(), FormatExact(min_nm), FormatExact(max_nm)));
    }
  }
  d.ThrowIfAny();
}

ParticleType SelectMode(const ParticleType& type, const std::string& mode_name) {
  ParticleType out = type;
  out.modes.clear();
  std::vector<std::string> names;
  for (const SizeMode& m : type.modes) {
    names.push_back(m.name);
    if (m.name == mode_name) out.modes.push_back(m);
  }
  if (out.modes.empty()) {
    throw UsageError(fmt::format("--mode: {} has no mode '{}' (modes: {})", type.file.string(), mode_name,
                                 fmt::join(names, ", ")));
  }
  return out;
}

std::string CanonicalParticleYaml(const ParticleType& type, const std::filesystem::path& dir) {
  YAML::Emitter out;
  out << YAML::Comment("canonical particle type " + type.name + " (written by skybake; do not edit)");
  out << YAML::BeginMap;
  out << YAML::Key << "modes" << YAML::Value << YAML::BeginSeq;
  for (const SizeMode& m : type.modes) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << m.name;
    out << YAML::Key << "refractive_index" << YAML::Value;
    EmitRefractiveIndex(out, m.index, dir);
    if (m.IsTable()) {
      out << YAML::Key << "size_table" << YAML::Value << m.table->file.lexically_relative(dir).generic_string();
    } else if (m.median_radius_um) {
      out << YAML::Key << "basis" << YAML::Value << (*m.basis == SizeBasis::kNumber ? "number" : "volume");
      out << YAML::Key << "median_radius_um" << YAML::Value << FormatExact(*m.median_radius_um);
    } else {
      out << YAML::Key << "effective_radius_um" << YAML::Value << FormatExact(*m.effective_radius_um);
    }
    if (!m.IsTable()) {
      out << YAML::Key << (m.width_is_sigma_g ? "sigma_g" : "ln_sigma_g") << YAML::Value << FormatExact(m.width_value);
      out << YAML::Key << "r_min_um" << YAML::Value << FormatExact(m.r_min_um);
      out << YAML::Key << "r_max_um" << YAML::Value << FormatExact(m.r_max_um);
    }
    out << YAML::Key << "weight" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << WeightKey(m.weight_kind) << YAML::Value << FormatExact(m.weight);
    out << YAML::EndMap;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace skybake::mie
