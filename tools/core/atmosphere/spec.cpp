#include "atmosphere/spec.h"

#include <cmath>
#include <set>

#include <fmt/format.h>

namespace skybake {

std::vector<double> AtmosphereSpec::AltitudeGrid() const {
  SKYBAKE_CHECK(planet.has_value() && grid.has_value());
  std::vector<double> z;
  const double top = planet->top_m, step = grid->altitude_step_m;
  const size_t n = static_cast<size_t>(std::ceil(top / step - 1e-9));
  for (size_t i = 0; i < n; ++i) z.push_back(static_cast<double>(i) * step);
  z.push_back(top);
  return z;
}

namespace {

// A positive number up to `max`.
NumberSpec PositiveUpTo(double max, const std::string& unit) {
  NumberSpec s = NumberSpec::Range(0.0, max, unit);
  s.min_inclusive = false;
  s.description = "a positive number up to " + FormatExact(max) + (unit.empty() ? "" : " in " + unit);
  return s;
}

}  // namespace

bool IsIdentifier(const std::string& s) {
  if (s.empty() || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return s.size() <= 64;
}

namespace {

// The absorbers section (both components: a layer without its coefficient would not parse).
void EmitAbsorbers(YAML::Emitter& out, const AtmosphereSpec& spec, const std::filesystem::path& dir) {
  if (spec.absorbers.empty()) return;
  out << YAML::Key << "absorbers" << YAML::Value << YAML::BeginSeq;
  for (const AbsorberSpec& a : spec.absorbers) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << a.name;
    out << YAML::Key << "absorption" << YAML::Value;
    EmitCoefficientSpectrum(out, a.absorption, dir);
    out << YAML::Key << "profile" << YAML::Value;
    EmitProfile(out, a.profile, dir);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

void EmitPlanet(YAML::Emitter& out, const AtmosphereSpec& spec) {
  if (!spec.planet) return;
  out << YAML::Key << "planet" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "radius_km" << YAML::Value << FormatExact(spec.planet->radius_m / 1e3);
  out << YAML::Key << "top_km" << YAML::Value << FormatExact(spec.planet->top_m / 1e3);
  out << YAML::EndMap;
}

// A layer's `name`: an identifier, unique among the layers of its list (`names`).
std::string LayerName(YamlMap& layer, const char* what, std::set<std::string>* names) {
  std::optional<YamlNode> node = layer.Get("name");
  if (!node) {
    layer.ErrorMissing("name", kIdentifierExpected);
    return {};
  }
  std::optional<std::string> name = node->ToString(kIdentifierExpected);
  if (!name) return {};
  if (!IsIdentifier(*name)) {
    node->ErrorExpected(kIdentifierExpected);
  } else if (!names->insert(*name).second) {
    node->Error(std::string(what) + " name '" + *name + "' is used twice");
  }
  return *name;
}

}  // namespace

AtmosphereSpec ParseAtmosphere(const YamlDocument& doc, const std::string& default_name) {
  AtmosphereSpec spec;
  spec.file = doc.display_name();
  YamlMap root = doc.RootMap();
  spec.name = default_name;
  if (std::optional<YamlNode> name = root.Get("name")) {
    // The name becomes a folder under outputs/ and a word of ninja command lines.
    if (std::optional<std::string> n = name->ToString(kIdentifierExpected)) {
      if (IsIdentifier(*n)) spec.name = *n;
      else name->ErrorExpected(kIdentifierExpected);
    }
  }

  if (std::optional<YamlMap> planet = root.OptionalMap("planet")) {
    PlanetSpec p;
    p.radius_m = planet->Number("radius_km", NumberSpec::Range(100.0, 1e5, "km"), 6371.0) * 1e3;
    p.top_m = planet->Number("top_km", NumberSpec::Range(1.0, 1000.0, "km"), 100.0) * 1e3;
    planet->Finish();
    spec.planet = p;
  }
  if (std::optional<YamlMap> observer = root.OptionalMap("observer")) {
    spec.observer_altitude_m = observer->NumberOr("altitude_km", NumberSpec::Range(0.0, 1000.0, "km"), 0.0) * 1e3;
    observer->Finish();
  }
  if (std::optional<YamlMap> grid = root.OptionalMap("grid")) {
    GridSpec g;
    g.altitude_step_m = grid->Number("altitude_step_m", NumberSpec::Range(1.0, 10000.0, "m"), 100.0);
    grid->Finish();
    spec.grid = g;
  }
  if (std::optional<YamlMap> air = root.OptionalMap("air")) {
    AirSpec a;
    if (std::optional<YamlNode> prof = air->Get("profile")) {
      if (std::optional<ProfileSpec> p = ParseProfile(*prof, {"ussa1976", "exponential", "table"}, true)) a.profile = *p;
    } else {
      air->ErrorMissing("profile", "ussa1976, {exponential: {...}} or {table: {...}}");
    }
    a.surface_number_density_m3 =
        air->NumberOr("surface_number_density_m3", PositiveUpTo(1e28, "m^-3"), a.surface_number_density_m3);
    if (std::optional<YamlNode> sc = air->Get("scattering")) {
      a.scattering = ParseCoefficientSpectrum(*sc);
      if (std::optional<YamlNode> co2 = air->Get("co2_ppm")) {
        co2->Error("co2_ppm sets the measured (Bodhaine 1999) cross-section; parametric air ('scattering') has none");
      }
      // rho_n < 0.5: the phase's gamma = rho / (2 - rho) must stay below 1/3 (Chandrasekhar 1950).
      NumberSpec rho = NumberSpec::Range(0.0, 0.5, "");
      rho.description = "a depolarisation factor rho_n from 0 to 0.5";
      a.depolarization = air->NumberOr("depolarization", rho, 0.0);
    } else {
      a.co2_ppm = air->NumberOr("co2_ppm", NumberSpec::Range(0.0, 10000.0, "ppm"), a.co2_ppm);
      if (std::optional<YamlNode> dep = air->Get("depolarization")) {
        dep->Error("depolarization belongs to parametric air ('scattering'); the measured cross-section carries "
                   "Bodhaine 1999's King factor");
      }
    }
    air->Finish();
    spec.air = a;
  }
  if (std::optional<YamlMap> ozone = root.OptionalMap("ozone")) {
    OzoneSpec o;
    if (std::optional<YamlNode> prof = ozone->Get("profile")) {
      if (std::optional<ProfileSpec> p = ParseProfile(*prof, {"table", "tent", "exponential"})) o.profile = *p;
    } else {
      ozone->ErrorMissing("profile", "{table: ...}, {tent: ...} or {exponential: ...}");
    }
    o.column_du = ozone->OptionalNumber("column_du", NumberSpec::Range(0.0, 1000.0, "Dobson units"));
    if (std::optional<YamlMap> xs = ozone->OptionalMap("cross_section")) {
      OzoneCrossSectionSpec c;
      std::string kind = xs->ExactlyOneOf({"table", "bogumil2003"});
      if (kind == "table") {
        c.kind = OzoneCrossSectionSpec::Kind::kTable;
        if (auto t = ParseSpectralTable(xs->Map("table"))) c.table = *t;
      } else if (kind == "bogumil2003") {
        c.kind = OzoneCrossSectionSpec::Kind::kBogumil2003;
        YamlMap b = xs->Map("bogumil2003");
        if (auto f = b.Path("file")) c.bogumil_file = *f;
        if (std::optional<YamlNode> t = b.Get("temperature_K")) {
          if (!(t->IsScalar() && t->raw().Scalar() == "local")) {
            c.temperature_k = t->ToNumber(NumberSpec::Range(203.0, 293.0, "K (the fit's range), or 'local'"));
          }
        }
        b.Finish();
      }
      xs->Finish();
      o.cross_section = c;
    }
    if (!o.column_du && !std::holds_alternative<TableProfile>(o.profile)) {
      ozone->ErrorMissing("column_du", "a non-negative number in Dobson units (needed unless the profile is a table of number densities)");
    }
    ozone->Finish();
    spec.ozone = o;
  }
  if (std::optional<std::vector<YamlNode>> layers = root.OptionalSeq("aerosols")) {
    std::set<std::string> names;
    for (const YamlNode& layer_node : *layers) {
      YamlMap layer = layer_node.ToMap("an aerosol layer (a mapping)");
      if (!layer.valid()) continue;
      AerosolLayerSpec a;
      a.name = LayerName(layer, "aerosol layer", &names);
      if (std::optional<YamlNode> particle = layer.Get("particle")) {
        // A particle type is named by its file name (mie/<name>.exr).
        a.particle = particle->ToPath();
        if (a.particle && !IsIdentifier(a.particle->stem().string())) {
          particle->Error("the particle type's file name '" + a.particle->stem().string() + "' is its name and must be " +
                          kIdentifierExpected + " with .yaml");
        }
      }
      if (std::optional<YamlNode> prof = layer.Get("profile")) {
        if (std::optional<ProfileSpec> p = ParseProfile(*prof, {"table", "exponential", "tent"})) a.profile = *p;
      } else {
        layer.ErrorMissing("profile", "{table: ...}, {exponential: ...} or {tent: ...}");
      }
      const bool parametric = layer.Has("extinction") || layer.Has("single_scattering_albedo") || layer.Has("phase");
      if (parametric) {
        if (std::optional<YamlNode> particle = layer.Get("particle")) {
          particle->Error("give either 'particle' (a measured type) or 'extinction', 'single_scattering_albedo' and "
                          "'phase' (parametric optics), not both");
        }
        if (std::optional<YamlNode> scale = layer.Get("scale")) {
          scale->Error("'scale' belongs to a particle type; a parametric layer's 'extinction' is its amount");
        }
        ParametricAerosolOptics po;
        bool ok = true;
        if (std::optional<YamlNode> e = layer.Get("extinction")) {
          std::optional<CoefficientSpectrum> c = ParseCoefficientSpectrum(*e);
          ok = ok && c.has_value();
          if (c) po.extinction = *c;
        } else {
          layer.ErrorMissing("extinction", "a coefficient spectrum such as {per_m: 4.44e-6}");
          ok = false;
        }
        if (std::optional<YamlNode> w = layer.Get("single_scattering_albedo")) {
          std::optional<AlbedoSpectrum> c = ParseAlbedoSpectrum(*w);
          ok = ok && c.has_value();
          if (c) po.single_scattering_albedo = *c;
        } else {
          layer.ErrorMissing("single_scattering_albedo", "a number from 0 to 1 (or {rgb: [...]} or {table: {...}})");
          ok = false;
        }
        if (std::optional<YamlNode> ph = layer.Get("phase")) {
          std::optional<PhaseSpec> c = ParsePhaseSpec(*ph);
          ok = ok && c.has_value();
          if (c) po.phase = *c;
        } else {
          layer.ErrorMissing("phase", "{henyey_greenstein: {g: ...}}, {cornette_shanks: {g: ...}} or {table: {...}}");
          ok = false;
        }
        if (ok) a.optics = po;
      }
      if (std::optional<YamlMap> scale = parametric ? std::nullopt : layer.OptionalMap("scale")) {
        std::string which = scale->ExactlyOneOf({"optical_depth_550nm", "peak_number_density_cm3"});
        if (which == "optical_depth_550nm") {
          a.scale = AerosolScale{AerosolScale::Kind::kOpticalDepth550nm,
                                 scale->Number(which, NumberSpec::Range(0.0, 100.0, ""), 0.0)};
        } else if (which == "peak_number_density_cm3") {
          a.scale = AerosolScale{AerosolScale::Kind::kPeakNumberDensity,
                                 scale->Number(which, NumberSpec::Range(0.0, 1e6, "cm^-3"), 0.0) * 1e6};
        }
        scale->Finish();
      }
      layer.Finish();
      spec.aerosols.push_back(std::move(a));
    }
  }
  if (std::optional<std::vector<YamlNode>> layers = root.OptionalSeq("absorbers")) {
    std::set<std::string> names;
    for (const YamlNode& layer_node : *layers) {
      YamlMap layer = layer_node.ToMap("an absorbing layer (a mapping)");
      if (!layer.valid()) continue;
      AbsorberSpec a;
      a.name = LayerName(layer, "absorbing layer", &names);
      if (std::optional<YamlNode> c = layer.Get("absorption")) {
        if (std::optional<CoefficientSpectrum> cs = ParseCoefficientSpectrum(*c)) a.absorption = *cs;
      } else {
        layer.ErrorMissing("absorption", "a coefficient spectrum such as {rgb_per_km: [6.5e-4, 1.881e-3, 8.5e-5]}");
      }
      if (std::optional<YamlNode> prof = layer.Get("profile")) {
        if (std::optional<ProfileSpec> p = ParseProfile(*prof, {"table", "exponential", "tent"})) a.profile = *p;
      } else {
        layer.ErrorMissing("profile", "{table: ...}, {exponential: ...} or {tent: ...}");
      }
      layer.Finish();
      spec.absorbers.push_back(std::move(a));
    }
  }
  if (std::optional<YamlMap> ground = root.OptionalMap("ground")) {
    GroundSpec g;
    if (std::optional<YamlNode> albedo = ground->Get("albedo")) {
      if (albedo->IsMap()) {
        g.albedo_table = ParseSpectralTable(albedo->ToMap());
      } else {
        g.albedo = albedo->ToNumber(NumberSpec::Range(0.0, 1.0, "(a constant albedo) or a table mapping"));
      }
    } else {
      ground->ErrorMissing("albedo", "a number from 0 to 1 or {file, wavelength_column, value_column}");
    }
    ground->Finish();
    spec.ground = g;
  }
  if (std::optional<YamlMap> sun = root.OptionalMap("sun")) {
    SunSpec s;
    YamlMap spectrum = sun->Map("spectrum");
    if (spectrum.valid() && spectrum.Has("constant_W_m2_nm")) {
      s.constant_w_m2_nm = spectrum.Number("constant_W_m2_nm", PositiveUpTo(1000.0, "W m^-2 nm^-1"), 1.0);
      spectrum.Finish();
    } else if (auto t = ParseSpectralTable(spectrum)) {
      s.spectrum = *t;
    }
    s.angular_diameter_deg = sun->NumberOr("angular_diameter_deg", NumberSpec::Range(0.01, 20.0, "degrees"), s.angular_diameter_deg);
    if (std::optional<YamlNode> ld = sun->Get("limb_darkening")) {
      if (ld->IsScalar() && ld->raw().Scalar() == "none") {
        s.limb_darkening_file.reset();
      } else {
        YamlMap m = ld->ToMap("'none' or {file: <Neckel & Labs coefficient table>}");
        s.limb_darkening_file = m.Path("file");
        m.Finish();
      }
    }
    sun->Finish();
    spec.sun = s;
  }
  root.Finish();

  // Cross-field checks.
  if (spec.planet && spec.observer_altitude_m >= spec.planet->top_m) {
    doc.diags().Add(FileLoc{doc.display_name(), 0},
                    fmt::format("observer.altitude_km ({}) must be below planet.top_km ({})",
                                FormatExact(spec.observer_altitude_m / 1e3), FormatExact(spec.planet->top_m / 1e3)));
  }
  doc.ThrowIfErrors();
  return spec;
}

AtmosphereSpec LoadAtmosphere(const std::filesystem::path& path) {
  YamlDocument doc = YamlDocument::Load(path);
  return ParseAtmosphere(doc, path.stem().string());
}

void RequireSections(const AtmosphereSpec& spec, const std::vector<std::string>& sections) {
  Diagnostics d;
  for (const std::string& s : sections) {
    bool present = (s == "planet" && spec.planet) || (s == "grid" && spec.grid) || (s == "air" && spec.air) ||
                   (s == "ozone" && spec.ozone) || (s == "ground" && spec.ground) || (s == "sun" && spec.sun);
    if (!present) d.Add(FileLoc{spec.file.string(), 0}, "missing section '" + s + "'");
  }
  d.ThrowIfAny();
}

std::string CanonicalProfilesYaml(const AtmosphereSpec& spec, const std::filesystem::path& dir) {
  YAML::Emitter out;
  out << YAML::Comment("canonical profile component of " + spec.name + " (written by skybake; do not edit)");
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << spec.name;
  EmitPlanet(out, spec);
  if (spec.grid) {
    out << YAML::Key << "grid" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "altitude_step_m" << YAML::Value << FormatExact(spec.grid->altitude_step_m);
    out << YAML::EndMap;
  }
  if (spec.air) {
    out << YAML::Key << "air" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "profile" << YAML::Value;
    EmitProfile(out, spec.air->profile, dir);
    if (std::holds_alternative<ExponentialProfile>(spec.air->profile)) {
      out << YAML::Key << "surface_number_density_m3" << YAML::Value << FormatExact(spec.air->surface_number_density_m3);
    }
    out << YAML::EndMap;
  }
  if (spec.ozone) {
    out << YAML::Key << "ozone" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "profile" << YAML::Value;
    EmitProfile(out, spec.ozone->profile, dir);
    if (spec.ozone->column_du) out << YAML::Key << "column_du" << YAML::Value << FormatExact(*spec.ozone->column_du);
    out << YAML::EndMap;
  }
  if (!spec.aerosols.empty()) {
    out << YAML::Key << "aerosols" << YAML::Value << YAML::BeginSeq;
    for (const AerosolLayerSpec& a : spec.aerosols) {
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << a.name;
      out << YAML::Key << "profile" << YAML::Value;
      EmitProfile(out, a.profile, dir);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  EmitAbsorbers(out, spec, dir);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace skybake

namespace skybake {

std::string CanonicalRenderYaml(const AtmosphereSpec& spec, const std::filesystem::path& dir) {
  YAML::Emitter out;
  out << YAML::Comment("canonical render component of " + spec.name + " (written by skybake; do not edit)");
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << spec.name;
  EmitPlanet(out, spec);
  out << YAML::Key << "observer" << YAML::Value << YAML::BeginMap << YAML::Key << "altitude_km" << YAML::Value
      << FormatExact(spec.observer_altitude_m / 1e3) << YAML::EndMap;
  if (spec.air) {
    out << YAML::Key << "air" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "profile" << YAML::Value;
    EmitProfile(out, spec.air->profile, dir);  // kind only matters for provenance; densities come from profiles.exr
    if (spec.air->scattering) {
      out << YAML::Key << "scattering" << YAML::Value;
      EmitCoefficientSpectrum(out, *spec.air->scattering, dir);
      out << YAML::Key << "depolarization" << YAML::Value << FormatExact(spec.air->depolarization);
    } else {
      out << YAML::Key << "co2_ppm" << YAML::Value << FormatExact(spec.air->co2_ppm);
    }
    out << YAML::EndMap;
  }
  if (spec.ozone) {
    out << YAML::Key << "ozone" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "profile" << YAML::Value;
    EmitProfile(out, spec.ozone->profile, dir);
    if (spec.ozone->column_du) out << YAML::Key << "column_du" << YAML::Value << FormatExact(*spec.ozone->column_du);
    if (spec.ozone->cross_section) {
      const OzoneCrossSectionSpec& c = *spec.ozone->cross_section;
      out << YAML::Key << "cross_section" << YAML::Value << YAML::BeginMap;
      if (c.kind == OzoneCrossSectionSpec::Kind::kTable) {
        out << YAML::Key << "table" << YAML::Value;
        EmitSpectralTable(out, c.table, dir);
      } else {
        out << YAML::Key << "bogumil2003" << YAML::Value << YAML::BeginMap;
        out << YAML::Key << "file" << YAML::Value << c.bogumil_file.lexically_relative(dir).generic_string();
        out << YAML::Key << "temperature_K" << YAML::Value << (c.temperature_k ? FormatExact(*c.temperature_k) : std::string("local"));
        out << YAML::EndMap;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  if (!spec.aerosols.empty()) {
    out << YAML::Key << "aerosols" << YAML::Value << YAML::BeginSeq;
    for (const AerosolLayerSpec& a : spec.aerosols) {
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << a.name;
      if (a.particle) out << YAML::Key << "particle" << YAML::Value << a.particle->lexically_relative(dir).generic_string();
      out << YAML::Key << "profile" << YAML::Value;
      EmitProfile(out, a.profile, dir);
      if (a.optics) {
        out << YAML::Key << "extinction" << YAML::Value;
        EmitCoefficientSpectrum(out, a.optics->extinction, dir);
        out << YAML::Key << "single_scattering_albedo" << YAML::Value;
        EmitAlbedoSpectrum(out, a.optics->single_scattering_albedo, dir);
        out << YAML::Key << "phase" << YAML::Value;
        EmitPhaseSpec(out, a.optics->phase, dir);
      }
      if (a.scale) {
        out << YAML::Key << "scale" << YAML::Value << YAML::BeginMap;
        if (a.scale->kind == AerosolScale::Kind::kOpticalDepth550nm) {
          out << YAML::Key << "optical_depth_550nm" << YAML::Value << FormatExact(a.scale->value);
        } else {
          out << YAML::Key << "peak_number_density_cm3" << YAML::Value << FormatExact(a.scale->value * 1e-6);
        }
        out << YAML::EndMap;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  EmitAbsorbers(out, spec, dir);
  if (spec.ground) {
    out << YAML::Key << "ground" << YAML::Value << YAML::BeginMap << YAML::Key << "albedo" << YAML::Value;
    if (spec.ground->albedo_table) EmitSpectralTable(out, *spec.ground->albedo_table, dir);
    else out << FormatExact(spec.ground->albedo.value_or(0.0));
    out << YAML::EndMap;
  }
  if (spec.sun) {
    out << YAML::Key << "sun" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "spectrum" << YAML::Value;
    if (spec.sun->constant_w_m2_nm) {
      out << YAML::BeginMap << YAML::Key << "constant_W_m2_nm" << YAML::Value << FormatExact(*spec.sun->constant_w_m2_nm)
          << YAML::EndMap;
    } else {
      EmitSpectralTable(out, spec.sun->spectrum, dir);
    }
    out << YAML::Key << "angular_diameter_deg" << YAML::Value << FormatExact(spec.sun->angular_diameter_deg);
    out << YAML::Key << "limb_darkening" << YAML::Value;
    if (spec.sun->limb_darkening_file) {
      out << YAML::BeginMap << YAML::Key << "file" << YAML::Value
          << spec.sun->limb_darkening_file->lexically_relative(dir).generic_string() << YAML::EndMap;
    } else {
      out << "none";
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace skybake
