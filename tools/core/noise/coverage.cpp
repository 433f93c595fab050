#include "noise/coverage.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

namespace skybake::noise {

double Curve::operator()(double x) const {
  x = std::clamp(x, 0.0, 1.0);
  const size_t k = static_cast<size_t>(std::upper_bound(s.begin(), s.end(), x) - s.begin());
  if (k == 0) return v.front();
  if (k >= s.size()) return v.back();
  const double t = (x - s[k - 1]) / (s[k] - s[k - 1]);
  return v[k - 1] + t * (v[k] - v[k - 1]);
}

std::array<double, 4> CoverageAt(const CloudType& type, double fade, double d, double z) {
  const double top = type.top_at_zero_density_m + (type.top_at_full_density_m - type.top_at_zero_density_m) * d;
  const double s = (z - type.base_m) / (top - type.base_m);
  // Fade-in e(d) = smoothstep(0, d_fade, d) = 3x^2 - 2x^3, x = clamp(d / d_fade, 0, 1).
  double e = d > 0.0 ? 1.0 : 0.0;
  if (fade > 0.0) {
    const double x = std::clamp(d / fade, 0.0, 1.0);
    e = x * x * (3.0 - 2.0 * x);
  }
  const bool inside = s >= 0.0 && s <= 1.0;
  return {inside ? d * type.height_modulation(s) : 0.0, inside ? e * type.low_frequency(s) : 0.0,
          inside ? e * type.mid_frequency(s) : 0.0, type.ambient(std::clamp(s, 0.0, 1.0))};
}

CoverageTexture BuildCoverageTexture(const CoverageSpec& spec) {
  CoverageTexture t;
  t.width = spec.density_texels;
  t.height = spec.altitude_texels;
  t.layers = static_cast<int>(spec.types.size());
  t.values.resize(static_cast<size_t>(t.layers) * t.height * t.width * 4);
  for (int l = 0; l < t.layers; ++l) {
    for (int j = 0; j < t.height; ++j) {
      for (int i = 0; i < t.width; ++i) {
        const std::array<double, 4> c =
            CoverageAt(spec.types[l], spec.noise_fade_in_density, spec.ColumnDensity(i), spec.RowAltitudeM(j));
        for (int k = 0; k < 4; ++k) t.values[((static_cast<size_t>(l) * t.height + j) * t.width + i) * 4 + k] = static_cast<float>(c[k]);
      }
    }
  }
  return t;
}

// ---------------------------------------------------------------------------- YAML

namespace {

// [[s, value], ...] with s from 0 to 1 strictly increasing and values in [0, 1].
Curve ParseCurve(YamlMap& m, const char* key) {
  Curve c;
  std::optional<YamlNode> node = m.Get(key);
  if (!node) {
    m.ErrorMissing(key, "a list of [height fraction, value] points from 0 to 1");
    c.s = {0.0, 1.0};
    c.v = {0.0, 0.0};
    return c;
  }
  const std::string expected = "a list of [height fraction, value] points, fractions from 0 to 1, values in [0, 1]";
  if (!node->IsSeq() || node->raw().size() < 2) {
    node->ErrorExpected(expected);
  } else {
    for (const YamlNode& p : node->Elements()) {
      std::optional<std::vector<double>> xy = p.ToNumberList(NumberSpec::Range(0.0, 1.0));
      if (!xy) continue;
      if (xy->size() != 2) {
        p.ErrorExpected("a [height fraction, value] pair");
        continue;
      }
      if (!c.s.empty() && (*xy)[0] <= c.s.back()) {
        p.Error(fmt::format("height fractions must increase strictly ({} after {})", FormatExact((*xy)[0]), FormatExact(c.s.back())));
      }
      c.s.push_back((*xy)[0]);
      c.v.push_back((*xy)[1]);
    }
    if (c.s.size() >= 2 && (c.s.front() != 0.0 || c.s.back() != 1.0)) {
      node->Error("the curve must start at height fraction 0 and end at 1");
    }
  }
  if (c.s.size() < 2) {
    c.s = {0.0, 1.0};
    c.v = {0.0, 0.0};
  }
  return c;
}

bool IsIdentifier(const std::string& s) {
  if (s.empty() || !std::islower(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char ch) {
    return std::islower(static_cast<unsigned char>(ch)) || std::isdigit(static_cast<unsigned char>(ch)) || ch == '_';
  });
}

}  // namespace

CoverageSpec ParseCoverageSpec(const YamlDocument& doc) {
  CoverageSpec spec;
  YamlMap root = doc.RootMap();
  YamlMap tex = root.Map("texture");
  spec.density_texels = static_cast<int>(tex.Integer("density_texels", 2, 4096, "an integer from 2 to 4096", 256));
  spec.altitude_texels = static_cast<int>(tex.Integer("altitude_texels", 2, 4096, "an integer from 2 to 4096", 128));
  tex.Finish();
  YamlMap alt = root.Map("altitude_km");
  spec.altitude_bottom_m = alt.Number("bottom", NumberSpec::NonNegative("km"), 0.5) * 1e3;
  spec.altitude_top_m = alt.Number("top", NumberSpec::Positive("km"), 8.5) * 1e3;
  if (alt.valid() && spec.altitude_top_m <= spec.altitude_bottom_m) alt.node().Error("top must be above bottom");
  alt.Finish();
  spec.noise_fade_in_density = root.NumberOr("noise_fade_in_density", NumberSpec::Range(0.0, 1.0), 0.1);

  std::set<std::string> names;
  std::vector<YamlNode> types = root.Seq("types");
  if (root.Has("types") && types.empty() && root.Get("types")->IsSeq()) root.Get("types")->Error("give at least one cloud type");
  for (const YamlNode& tn : types) {
    YamlMap m = tn.ToMap("a cloud type (a mapping)");
    if (!m.valid()) continue;
    CloudType t;
    t.name = m.String("name", "a lowercase identifier");
    if (!t.name.empty()) {
      if (!IsIdentifier(t.name)) m.Get("name")->ErrorExpected("a lowercase identifier (a-z, 0-9, _; starting with a letter)");
      else if (!names.insert(t.name).second) m.Get("name")->Error("cloud type '" + t.name + "' is given twice");
    }
    t.base_m = m.Number("base_km", NumberSpec::NonNegative("km"), 1.0) * 1e3;
    YamlMap top = m.Map("top_km");
    t.top_at_zero_density_m = top.Number("at_zero_density", NumberSpec::Positive("km"), 1.5) * 1e3;
    t.top_at_full_density_m = top.Number("at_full_density", NumberSpec::Positive("km"), 3.0) * 1e3;
    if (top.valid()) {
      if (t.top_at_zero_density_m <= t.base_m) {
        top.node().Error(fmt::format("at_zero_density ({} km) must be above base_km ({} km)",
                                     FormatExact(t.top_at_zero_density_m / 1e3), FormatExact(t.base_m / 1e3)));
      } else if (t.top_at_full_density_m < t.top_at_zero_density_m) {
        top.node().Error("at_full_density must not be below at_zero_density (denser cumulus grow taller)");
      } else if (t.base_m < spec.altitude_bottom_m || t.top_at_full_density_m > spec.altitude_top_m) {
        top.node().Error(fmt::format("the cloud spans {} to {} km but the texture covers {} to {} km (altitude_km)",
                                     FormatExact(t.base_m / 1e3), FormatExact(t.top_at_full_density_m / 1e3),
                                     FormatExact(spec.altitude_bottom_m / 1e3), FormatExact(spec.altitude_top_m / 1e3)));
      }
    }
    top.Finish();
    t.height_modulation = ParseCurve(m, "height_modulation");
    t.low_frequency = ParseCurve(m, "low_frequency");
    t.mid_frequency = ParseCurve(m, "mid_frequency");
    t.ambient = ParseCurve(m, "ambient");
    m.Finish();
    spec.types.push_back(std::move(t));
  }
  root.Finish();
  doc.ThrowIfErrors();
  return spec;
}

CoverageSpec LoadCoverageSpec(const std::filesystem::path& path) { return ParseCoverageSpec(YamlDocument::Load(path)); }

std::string CanonicalCoverageYaml(const CoverageSpec& s) {
  YAML::Emitter out;
  auto curve = [&](const Curve& c) {
    out << YAML::Flow << YAML::BeginSeq;
    for (size_t k = 0; k < c.s.size(); ++k) out << YAML::Flow << YAML::BeginSeq << FormatExact(c.s[k]) << FormatExact(c.v[k]) << YAML::EndSeq;
    out << YAML::EndSeq;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "texture" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "density_texels"
      << YAML::Value << s.density_texels << YAML::Key << "altitude_texels" << YAML::Value << s.altitude_texels
      << YAML::EndMap;
  out << YAML::Key << "altitude_km" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "bottom"
      << YAML::Value << FormatExact(s.altitude_bottom_m / 1e3) << YAML::Key << "top" << YAML::Value
      << FormatExact(s.altitude_top_m / 1e3) << YAML::EndMap;
  out << YAML::Key << "noise_fade_in_density" << YAML::Value << FormatExact(s.noise_fade_in_density);
  out << YAML::Key << "types" << YAML::Value << YAML::BeginSeq;
  for (const CloudType& t : s.types) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << t.name;
    out << YAML::Key << "base_km" << YAML::Value << FormatExact(t.base_m / 1e3);
    out << YAML::Key << "top_km" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "at_zero_density"
        << YAML::Value << FormatExact(t.top_at_zero_density_m / 1e3) << YAML::Key << "at_full_density" << YAML::Value
        << FormatExact(t.top_at_full_density_m / 1e3) << YAML::EndMap;
    out << YAML::Key << "height_modulation" << YAML::Value;
    curve(t.height_modulation);
    out << YAML::Key << "low_frequency" << YAML::Value;
    curve(t.low_frequency);
    out << YAML::Key << "mid_frequency" << YAML::Value;
    curve(t.mid_frequency);
    out << YAML::Key << "ambient" << YAML::Value;
    curve(t.ambient);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace skybake::noise
