#include "fog/fog_luts.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "color/exr_color.h"
#include "fog/fog_residual_png.h"
#include "io/yaml.h"
#include "lut/dds.h"
#include "lut/ktx2.h"
#include "lut/packed_files.h"
#include "skybake/version.h"

namespace skybake::fog {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

using Json = nlohmann::ordered_json;

std::string Join(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : " ") + FormatExact(x);
  return s;
}

std::string ModelText(const FogParams& p) {
  return fmt::format(
      "Fog(dir, d) = LUT(dir) (1 - exp(-a theta^p x)) / (1 - exp(-a theta^p)) per Linear Rec.2020 channel, "
      "x = min(d / D, 1), D = distance from the observer to the cut sphere (altitude {} m) along dir, directions below "
      "the horizon clamped to it; theta = {}; a, p {}; docs/fog.md",
      FormatExact(p.cut_altitude_m),
      p.angle == AngleDefinition::kPath ? "(cut - observer altitude) / D (path)" : "elevation / 90 deg (elevation)",
      p.slices.empty()    ? "global (one pair per channel)"
      : p.node_v.empty()  ? "per slice of the fog LUT, blended between slices as the LUT"
                          : "per slice of the fog LUT (a also per elevation node, linear in v = (elevation/90 deg)^(1/2)), "
                            "blended between slices as the LUT");
}

std::string PerSliceText() {
  return "a and p per slice of the fog LUT (row k: slice k, R, G, B): fitted per depth table, ln a and p linear in the "
         "sun zenith angle between the tables, constant beyond the first and the last; the runtime blends rows i and "
         "i + 1 linearly with the LUT's slice weight t (a = (1 - t) a_i + t a_i+1; beyond the last slice the last row); "
         "docs/fog.md";
}

std::string ElevationNodesText() {
  return "a per slice (outer list) and elevation node (inner list: nodes at v = (elevation/90 deg)^(1/2), the depth "
         "tables' elevations) per channel: the depth exponent is k = a(v) theta^p with a linear in v between the nodes "
         "(clamped at the ends) and p the slice's; fitted per depth table and elevation as a = k / theta^p, ln a linear "
         "in the sun zenith angle between the tables; docs/fog.md";
}

// A packed texture's inspection image (lut/packed_files.h) with the quantity it holds.
ExrImage InspectionImage(int width, int height, const lut::PackedTexture& t, const Provenance& prov, const std::string& quantity) {
  ExrImage img = lut::PackedInspectionImage(
      width, height, t, prov,
      "R, G, B: the packed texels as a shader reads them divided by the scale (physical units, Linear Rec.2020); "
      "input_R/G/B: before packing; clamp_flags: 1 = above the format's largest value, 2 = negative (outside "
      "Rec.2020), 4 = denormal (bit OR)");
  img.strings["skybake.quantity"] = quantity;
  return img;
}

Json StatsJson(const ErrorStats& s) {
  return Json{{"samples", s.count},
              {"rms", s.rms},
              {"max", s.max},
              {"channel_rms", {{"R", s.channel_rms[0]}, {"G", s.channel_rms[1]}, {"B", s.channel_rms[2]}}},
              {"max_at",
               {{"sun_zenith_deg", s.max_sun_zenith_deg},
                {"elevation_deg", s.max_elevation_deg},
                {"azimuth_from_sun_deg", s.max_azimuth_deg},
                {"depth_m", s.max_depth_m},
                {"x", s.max_x}}}};
}

Json ProductJson(const ProductStats& p, const FogRender& r) {
  Json j;
  j["all"] = StatsJson(p.all);
  j["near_camera"] = StatsJson(p.near);
  j["far"] = StatsJson(p.far);
  j["horizon"] = StatsJson(p.horizon);
  j["near_camera_at_horizon"] = StatsJson(p.near_horizon);
  j["infinite_depth"] = StatsJson(p.infinite_depth);
  Json per = Json::array();
  for (size_t s = 0; s < r.tables.size(); ++s) {
    per.push_back({{"sun_zenith_deg", r.tables[s].sun_zenith_deg},
                   {"rms", p.all_per_sun[s].rms},
                   {"max", p.all_per_sun[s].max},
                   {"near_camera_rms", p.near_per_sun[s].rms},
                   {"near_camera_max", p.near_per_sun[s].max}});
  }
  j["per_sun"] = per;
  return j;
}

Json FitJson(const std::array<FitResult, 3>& f, bool per_channel) {
  Json j = Json::array();
  for (int c = 0; c < (per_channel ? 3 : 1); ++c) {
    j.push_back({{"channel", per_channel ? std::string(1, "RGB"[c]) : std::string("luminance")},
                 {"a", f[c].a},
                 {"p", f[c].p},
                 {"rms_log_residual", f[c].rms_log},
                 {"samples_used", f[c].used},
                 {"samples_left_out", f[c].rejected},
                 {"evaluations", f[c].evaluations},
                 {"p_fitted", f[c].p_fitted},
                 {"at_bound", f[c].at_bound},
                 {"fallback", f[c].fallback},
                 {"status", f[c].status}});
  }
  return j;
}

Json PackJson(const lut::PackedTexture& t) {
  const lut::PackStats& s = t.stats;
  return Json{{"size", {t.width, t.height, t.depth}},
              {"scale", t.scale},
              {"texels", s.texels},
              {"clamped_above_max", s.clamped_high},
              {"negative_rec2020", s.negative_texels},
              {"denormal", s.denormal_texels},
              {"luminance_relative_error_rms", s.y_rel_rms},
              {"luminance_relative_error_max", s.y_rel_max}};
}

Json ProvenanceJson(const Provenance& p) {
  Json in = Json::array();
  for (const auto& [path, hash] : p.inputs) in.push_back({{"path", path}, {"xxh3", hash}});
  return Json{{"tool", p.tool}, {"version", kVersion}, {"parameters", p.parameters}, {"inputs", in}};
}


// nlohmann's dump(2) puts every number of an array on its own line; arrays holding only numbers
// are written on one line instead (the per-slice tables would otherwise be 100 KB of indentation).
std::string CompactNumberArrays(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '[') {
      size_t j = i + 1;
      bool numeric = true, any = false;
      while (j < text.size() && text[j] != ']') {
        const char c = text[j];
        if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E') {
          any = true;
        } else if (!(c == ',' || c == ' ' || c == '\n')) {
          numeric = false;
          break;
        }
        ++j;
      }
      if (numeric && any && j < text.size()) {
        out += '[';
        bool space = false;
        for (size_t k = i + 1; k < j; ++k) {
          const char c = text[k];
          if (c == ' ' || c == '\n') continue;
          if (space) out += ' ';
          space = false;
          out += c;
          if (c == ',') space = true;
        }
        out += ']';
        i = j + 1;
        continue;
      }
    }
    out += text[i++];
  }
  return out;
}

// The depth function's parameters as a tiny texture for a shader (docs/fog.md, "LUTs"):
// R32G32B32A32_SFLOAT (a reaches 1e-5 on a Rayleigh-only sky: below half's normal range), W = 1 + nodes (1 without elevation nodes), H = slices, 2 layers (0 fog, 1
// shadowed fog); texel (0, k) = (p_R, p_G, p_B, 0) of slice k, texel (1 + j, k) = (a_R, a_G, a_B, 1)
// at elevation node j. Global parameters are written as the same row in every slice.
ktx2::Texture ParamsTexture(const FogProducts& p, const std::vector<double>& slice_zenith_deg, const Provenance& prov) {
  const FogParams& par = p.params;
  const size_t n_slices = slice_zenith_deg.size(), nodes = std::max<size_t>(par.node_v.size(), 1);
  std::vector<float> v;
  for (int prod = 0; prod < 2; ++prod) {
    for (size_t k = 0; k < n_slices; ++k) {
      const FogParams::Slice q = par.slices.empty()
                                     ? FogParams::Slice{par.a, par.p, par.a_shadowed, par.p_shadowed, {}, {}}
                                     : par.slices[k];
      const std::array<double, 3>& pp = prod ? q.p_shadowed : q.p;
      for (double x : pp) v.push_back(static_cast<float>(x));
      v.push_back(0.0f);
      const std::vector<std::array<double, 3>>& an = prod ? q.a_shadowed_nodes : q.a_nodes;
      for (size_t j = 0; j < nodes; ++j) {
        const std::array<double, 3>& a = an.empty() ? (prod ? q.a_shadowed : q.a) : an[j];
        for (double x : a) v.push_back(static_cast<float>(x));
        v.push_back(1.0f);
      }
    }
  }
  ktx2::Texture tex;
  tex.format = ktx2::R32G32B32A32Sfloat();
  tex.width = static_cast<uint32_t>(1 + nodes);
  tex.height = static_cast<uint32_t>(n_slices);
  tex.layers = 2;
  tex.data = ktx2::EncodeTexels(tex.format, v);
  ktx2::SetProvenance(tex, prov);
  ktx2::SetString(tex, "KTXorientation", "rd");
  ktx2::SetString(tex, "skybake.basis_sky", p.sky);
  ktx2::SetString(tex, "skybake.quantity",
                  "GT7 fog depth function k = a theta^p per Linear Rec.2020 channel (docs/fog.md): layer 0 the fog, layer 1 "
                  "the shadowed fog; row k = slice k of the fog LUT; texel 0 = (p_R, p_G, p_B, 0), texel 1 + j = (a_R, a_G, "
                  "a_B, 1) at elevation node j (one node: a for every elevation); float32 of the parameter file's doubles");
  std::string nv, sz;
  for (double x : par.node_v) nv += (nv.empty() ? "" : " ") + FormatExact(x);
  for (double x : slice_zenith_deg) sz += (sz.empty() ? "" : " ") + FormatExact(x);
  ktx2::SetString(tex, "skybake.fog.parameters_mode", ParamModeName(p.options.params));
  ktx2::SetString(tex, "skybake.fog.elevation_nodes_v", nv.empty() ? "none" : nv);
  ktx2::SetString(tex, "skybake.slice_zenith_deg", sz);
  ktx2::SetString(tex, "skybake.sampling",
                  "per slice: a linear in v = (elevation/90 deg)^(1/2) between the nodes (uniform in v for the pipeline's "
                  "depth tables: texel coordinate (1 + v (W - 2) + 1/2)/W), clamped at the ends; rows i and i + 1 blended "
                  "with the fog LUT's slice weight t (linear in the sun zenith angle); beyond the last slice the last row");
  return tex;
}


// The fog or shadowed fog LUT as KTX2: lut-pack's sky texture layout and keys (lut::SkyKtx2), so
// that lut::SkyLutDecoder reads it; the quantity and the night rule are the fog's.
std::string FogKtx2(const FogRender& r, const FogProducts& p, const std::string& P, const Provenance& prov,
                    const lut::PackedTexture& t, bool shadowed, bool array) {
  lut::LutSet set;
  set.options.night_end_zenith_deg = p.options.night_end_zenith_deg;
  lut::SkyLutProduct sp;
  sp.name = p.sky;
  sp.render = &p.layout;
  sp.sky = t;
  sp.night_rgb = {0, 0, 0};
  ktx2::Texture tex = lut::SkyKtx2(set, sp, array, prov);
  ktx2::SetString(tex, "skybake.quantity",
                  std::string(shadowed ? "shadowed fog (no single-scattered sun)" : "fog") +
                      " of the whole low-atmosphere segment (x = 1): in-scattered radiance (cd/m^2 of luminance) in "
                      "Linear Rec.2020, times skybake.scale; texel (x, y, slice) is the direction of the GT7 sphere "
                      "mapping at " +
                      std::string(p.texel_grid == gt7::TexelGrid::kNodes ? "u = x/(W - 1), v = y/(H - 1)" : "u = (x + 1/2)/W, v = (y + 1/2)/H") +
                      " for the sun zenith angle of the slice; directions below the horizon hold the horizon's value");
  ktx2::SetString(tex, "skybake.night",
                  fmt::format("below the last slice (sun zenith {} deg) the decoded fog moves linearly to 0, reached at "
                              "sun zenith {} deg",
                              FormatExact(r.slice_zenith_deg.back()), FormatExact(p.options.night_end_zenith_deg)));
  ktx2::SetString(tex, "skybake.fog.model", ModelText(p.params));
  ktx2::SetString(tex, "skybake.fog.cut_altitude_m", FormatExact(r.cut_altitude_m));
  ktx2::SetString(tex, "skybake.fog.parameters", P + ".json");
  ktx2::SetString(tex, "skybake.fog.parameters_texture", P + "_params.ktx2");
  ktx2::SetString(tex, "skybake.fog.parameters_mode", ParamModeName(p.options.params));
  if (p.texel_grid == gt7::TexelGrid::kNodes) {
    ktx2::SetString(tex, "skybake.texel_grid", gt7::TexelGridName(p.texel_grid));
    ktx2::SetString(tex, "skybake.sphere_mapping", p.layout.sphere.Describe(p.texel_grid));
    ktx2::SetString(tex, "skybake.sampling",
                    "texel (x, y) is the node u = x/(W - 1), v = y/(H - 1) of the sphere mapping: sample at texel "
                    "coordinates ((u (W - 1) + 1/2)/W, (v (H - 1) + 1/2)/H), bilinear, clamp-to-edge; slices as lut-pack's "
                    "sky LUTs: slice coordinate s of the sun zenith theta from the time mapping, slices i = min(floor(s), "
                    "N - 2) and i + 1, each read with its own sphere-mapping family at the target sun zenith (sun-aligned "
                    "slices at min(theta, threshold zenith)), blended geometrically per channel, max(a, 1e-6)^(1 - t) "
                    "max(b, 1e-6)^t with t = (theta - theta_i)/(theta_i+1 - theta_i) (docs/fog.md, docs/lut-pack.md)");
  }
  return ktx2::EncodeKtx2(tex);
}

std::string Dds(const lut::PackedTexture& t, bool volume) { return dds::EncodeDds(lut::PackedDds(t, volume)); }

std::string AttenuationQuantity() {
  return "transmittance from the observer to normalised depth x along the view, for sunlight, per Linear Rec.2020 channel: "
        "[E0 T]_c / [E0]_c (1), times skybake.scale";
}

std::string AttenuationAxes() {
  return "u = x^(1/3) (x = depth / D, D the distance to the cut sphere), v = (elevation / 90 deg)^(1/2) (below the horizon: "
        "0); texel (i, j) is the node u = i/(W-1), v = j/(H-1): sample at ((u (W-1) + 1/2)/W, (v (H-1) + 1/2)/H), "
        "bilinear, clamp to edge";
}

std::string AttenuationKtx2(const FogRender& r, const FogProducts& p, const Provenance& prov) {
  ktx2::Texture tex;
  tex.format = ktx2::B10G11R11UfloatPack32();
  tex.width = static_cast<uint32_t>(p.attenuation.width);
  tex.height = static_cast<uint32_t>(p.attenuation.height);
  ktx2::SetProvenance(tex, prov);
  ktx2::SetString(tex, "KTXorientation", "rd");
  ktx2::SetString(tex, "skybake.basis_sky", p.sky);
  ktx2::SetString(tex, "skybake.quantity", AttenuationQuantity());
  ktx2::SetString(tex, "skybake.colorspace", ocio_names::kLinearRec2020);
  ktx2::SetString(tex, "skybake.scale", FormatExact(p.attenuation.scale));
  ktx2::SetString(tex, "skybake.sampling", AttenuationAxes());
  ktx2::SetString(tex, "skybake.fog.cut_altitude_m", FormatExact(r.cut_altitude_m));
  ktx2::SetString(tex, "skybake.fog.observer_altitude_m", FormatExact(r.observer_altitude_m));
  ktx2::SetString(tex, "skybake.fog.planet_radius_m", FormatExact(r.planet_radius_m));
  tex.data = p.attenuation.bytes;
  return ktx2::EncodeKtx2(tex);
}

// The inspection EXR: the three textures decoded, their inputs and clamp flags.
std::string InspectionExr(const FogRender& r, const FogProducts& p, const Provenance& prov) {
  std::vector<ExrPart> parts;
  const std::string layout = fmt::format("{} slices of {}x{} stacked top to bottom", p.fog.depth, p.fog.width, p.fog.height);
  ExrImage f = InspectionImage(p.fog.width, p.fog.height * p.fog.depth, p.fog, prov, "fog LUT (x = 1), cd/m^2");
  f.strings["skybake.layout"] = layout;
  f.strings["skybake.slice_zenith_deg"] = Join(r.slice_zenith_deg);
  ExrImage s = InspectionImage(p.shadowed.width, p.shadowed.height * p.shadowed.depth, p.shadowed, prov,
                               "shadowed fog LUT (x = 1), cd/m^2");
  s.strings["skybake.layout"] = layout;
  s.strings["skybake.slice_zenith_deg"] = Join(r.slice_zenith_deg);
  ExrImage a = InspectionImage(p.attenuation.width, p.attenuation.height, p.attenuation, prov, AttenuationQuantity());
  a.strings["skybake.sampling"] = AttenuationAxes();
  parts.push_back({"fog", std::move(f)});
  parts.push_back({"shadowed", std::move(s)});
  parts.push_back({"attenuation", std::move(a)});
  return EncodeExrParts(parts);
}

// The parameter file: the model, its parameters (global, per slice, per elevation node), the files.
std::string ParametersJson(const FogRender& r, const FogProducts& p, const std::string& P, const Provenance& prov) {
  const FogGeometry geo = r.geometry();
  Json j;
  j["basis_sky"] = p.sky;
  Json m;
  m["equation"] = ModelText(p.params);
  m["angle"] = AngleDefinitionName(p.params.angle);
  m["channels"] = p.options.per_channel ? "rgb (one a, p per Linear Rec.2020 channel)" : "luminance (one a, p for R, G, B)";
  m["colorspace"] = ocio_names::kLinearRec2020;
  m["planet_radius_m"] = p.params.planet_radius_m;
  m["observer_altitude_m"] = p.params.observer_altitude_m;
  m["cut_altitude_m"] = p.params.cut_altitude_m;
  m["boundary_distance_zenith_m"] = geo.BoundaryDistanceM(1.0);
  m["boundary_distance_horizon_m"] = geo.BoundaryDistanceM(0.0);
  m["units"] = "a, p, x and theta are dimensionless; depths in m; LUT radiance in cd/m^2 (Linear Rec.2020)";
  m["parameters"] = ParamModeName(p.options.params);
  m["fog"] = {{"a", p.params.a}, {"p", p.params.p}};
  m["shadowed"] = {{"a", p.params.a_shadowed}, {"p", p.params.p_shadowed}};
  if (!p.params.slices.empty()) {
    Json fa = Json::array(), fp = Json::array(), sa = Json::array(), sp = Json::array();
    for (const FogParams::Slice& q : p.params.slices) {
      fa.push_back(q.a);
      fp.push_back(q.p);
      sa.push_back(q.a_shadowed);
      sp.push_back(q.p_shadowed);
    }
    m["per_slice"] = {{"description", PerSliceText()},
                      {"sun_zenith_deg", r.slice_zenith_deg},
                      {"fog", {{"a", fa}, {"p", fp}}},
                      {"shadowed", {{"a", sa}, {"p", sp}}}};
    if (!p.params.node_v.empty()) {
      Json ea = Json::array(), esa = Json::array();
      for (const FogParams::Slice& q : p.params.slices) {
        ea.push_back(q.a_nodes);
        esa.push_back(q.a_shadowed_nodes);
      }
      std::vector<double> el;
      for (double v : p.params.node_v) el.push_back(90.0 * v * v);
      m["per_slice"]["elevation_nodes"] = {{"description", ElevationNodesText()},
                                           {"v", p.params.node_v},
                                           {"elevation_deg", el},
                                           {"fog", {{"a", ea}}},
                                           {"shadowed", {{"a", esa}}}};
    }
  }
  j["model"] = m;
  j["files"] = {{"fog", P + ".ktx2"},
                {"fog_array", P + "_array.ktx2"},
                {"fog_dds", P + ".dds"},
                {"shadowed", P + "_shadowed.ktx2"},
                {"shadowed_array", P + "_shadowed_array.ktx2"},
                {"shadowed_dds", P + "_shadowed.dds"},
                {"attenuation", P + "_attenuation.ktx2"},
                {"attenuation_dds", P + "_attenuation.dds"},
                {"parameters_texture", P + "_params.ktx2"},
                {"report", P + "_report.json"}};
  j["skybake"] = ProvenanceJson(prov);
  return CompactNumberArrays(j.dump(2)) + "\n";
}

// The report: the reference, the definitions, the fits, the diagnostics, the errors and the packing.
std::string ReportJson(const FogRender& r, const FogProducts& p, const Provenance& prov) {
  Json j;
  j["basis_sky"] = p.sky;
  j["reference"] = {{"file", r.path},
                    {"method", r.method},
                    {"method_settings", r.method_description},
                    {"sun_zenith_deg", [&] {
                       std::vector<double> v;
                       for (const FogDepthTable& t : r.tables) v.push_back(t.sun_zenith_deg);
                       return v;
                     }()},
                    {"elevation_deg", r.elevation_deg},
                    {"azimuth_from_sun_deg", r.azimuth_deg},
                    {"depth_x", r.depth_x},
                    {"noise_rms_relative", p.reference_noise_rms},
                    {"samples_with_zero_fog", p.excluded_samples}};
  j["definitions"] = {
      {"error", "relative luminance error Y_model / Y_reference - 1 (Y from Linear Rec.2020 by OCIO); channel_rms: the "
                "same per Rec.2020 channel"},
      {"fit", "the model with the exact reference at x = 1: LUT(dir) = Fog_ref(dir, 1), and the (a, p) the evaluator uses "
              "at the table's sun angle (the depth function's error)"},
      {"evaluator", "fog/fog_evaluator.h on the packed textures: mappings, slice interpolation, R11G11B10F and the depth "
                    "function (what a game gets)"},
      {"near_camera", fmt::format("depth <= {} m", FormatExact(p.options.near_depth_m))},
      {"horizon", fmt::format("elevation <= {} deg", FormatExact(p.options.horizon_elevation_deg))},
      {"infinite_depth", "x = 1: the LUT against the direct render of the same directions (consistency)"}};
  Json tables = Json::array();
  for (size_t s = 0; s < r.tables.size(); ++s) {
    tables.push_back({{"sun_zenith_deg", r.tables[s].sun_zenith_deg},
                      {"used_by_the_fit", static_cast<bool>(p.table_in_fit[s])},
                      {"fog", FitJson(p.table_fit_fog[s], p.options.per_channel)},
                      {"shadowed", FitJson(p.table_fit_shadowed[s], p.options.per_channel)}});
  }
  j["fit"] = {{"angle", AngleDefinitionName(p.params.angle)},
              {"parameters", ParamModeName(p.options.params)},
              {"fog", FitJson(p.fit_fog, p.options.per_channel)},
              {"shadowed", FitJson(p.fit_shadowed, p.options.per_channel)},
              {"per_table", tables}};
  Json diag = Json::array();
  for (const FitDiagnostic& d : p.diagnostics) {
    diag.push_back({{"name", d.name}, {"description", d.description}, {"all", StatsJson(d.all)},
                    {"near_camera", StatsJson(d.near)}, {"horizon", StatsJson(d.horizon)}});
  }
  j["fit_diagnostics"] = diag;
  j["errors"] = {{"fog", {{"fit", ProductJson(p.fog_fit, r)}, {"evaluator", ProductJson(p.fog_eval, r)}}},
                 {"shadowed", {{"fit", ProductJson(p.shadowed_fit, r)}, {"evaluator", ProductJson(p.shadowed_eval, r)}}}};
  j["attenuation"] = {{"rms_abs", {{"R", p.attenuation_rms_abs[0]}, {"G", p.attenuation_rms_abs[1]}, {"B", p.attenuation_rms_abs[2]}}},
                      {"max_abs", {{"R", p.attenuation_max_abs[0]}, {"G", p.attenuation_max_abs[1]}, {"B", p.attenuation_max_abs[2]}}}};
  j["packing"] = {{"fog", PackJson(p.fog)}, {"shadowed", PackJson(p.shadowed)}, {"attenuation", PackJson(p.attenuation)}};
  j["skybake"] = ProvenanceJson(prov);
  return CompactNumberArrays(j.dump(2)) + "\n";
}

// The residual maps as a multi-part EXR table, one part per depth table.
std::string ResidualsExr(const FogRender& r, const FogProducts& p, const Provenance& prov) {
  const FogGeometry geo = r.geometry();
  std::vector<ExrPart> parts;
  const ExrAxis dx{"depth_x", "1", "normalised depth x", r.depth_x};
  const ExrAxis az{"azimuth", "deg", "view azimuth from the sun", r.azimuth_deg};
  const ExrAxis el{"elevation", "deg", "view elevation", r.elevation_deg};
  for (size_t s = 0; s < r.tables.size(); ++s) {
    ExrTable t;
    t.axes = {dx, az, el};
    t.channels = {"fog_fit_Y", "fog_eval_Y", "shadowed_fit_Y", "shadowed_eval_Y", "fog_eval_R", "fog_eval_G", "fog_eval_B", "depth_m"};
    t.channel_units = {"1", "1", "1", "1", "1", "1", "1", "m"};
    const size_t n = p.residual_fog_fit[s].size();
    for (size_t i = 0; i < n; ++i) {
      const size_t e = i / (r.azimuth_deg.size() * r.depth_x.size()), j = i % r.depth_x.size();
      const double depth = r.depth_x[j] * geo.BoundaryDistanceM(std::sin(r.elevation_deg[e] * kDeg));
      for (float v : {p.residual_fog_fit[s][i], p.residual_fog_eval[s][i], p.residual_shadowed_fit[s][i],
                      p.residual_shadowed_eval[s][i], p.residual_fog_eval_rgb[s][i][0], p.residual_fog_eval_rgb[s][i][1],
                      p.residual_fog_eval_rgb[s][i][2], static_cast<float>(depth)}) {
        t.values.push_back(v);
      }
    }
    ExrImage img = TableToImage(t);
    img.strings["skybake.quantity"] =
        "relative error of the fog model vs the reference (Y_model / Y_ref - 1; NaN where the reference is 0): fit = "
        "exact LUT x depth function, eval = the evaluator on the packed textures";
    img.doubles["skybake.sun_zenith_deg"] = r.tables[s].sun_zenith_deg;
    SetProvenance(img, prov);
    parts.push_back({fmt::format("residual.sza_{:06.2f}", r.tables[s].sun_zenith_deg), std::move(img)});
  }
  return EncodeExrParts(parts);
}

}  // namespace

std::map<std::string, std::string> EncodeFogProducts(const FogRender& r, const FogProducts& p, const std::string& P,
                                                     const Provenance& prov, const Font& font) {
  std::map<std::string, std::string> out;
  out[P + ".ktx2"] = FogKtx2(r, p, P, prov, p.fog, false, false);
  out[P + "_array.ktx2"] = FogKtx2(r, p, P, prov, p.fog, false, true);
  out[P + ".dds"] = Dds(p.fog, true);
  out[P + "_shadowed.ktx2"] = FogKtx2(r, p, P, prov, p.shadowed, true, false);
  out[P + "_shadowed_array.ktx2"] = FogKtx2(r, p, P, prov, p.shadowed, true, true);
  out[P + "_shadowed.dds"] = Dds(p.shadowed, true);
  out[P + "_attenuation.ktx2"] = AttenuationKtx2(r, p, prov);
  out[P + "_attenuation.dds"] = Dds(p.attenuation, false);
  out[P + "_params.ktx2"] = ktx2::EncodeKtx2(ParamsTexture(p, r.slice_zenith_deg, prov));
  out[P + ".exr"] = InspectionExr(r, p, prov);
  out[P + ".json"] = ParametersJson(r, p, P, prov);
  out[P + "_report.json"] = ReportJson(r, p, prov);
  out[P + "_residuals.exr"] = ResidualsExr(r, p, prov);
  out[P + "_residuals.png"] = ResidualPng(r, p, font);
  return out;
}

std::vector<std::string> FogProductFiles(const std::string& P) {
  return {P + ".json",         P + ".ktx2",          P + "_array.ktx2",          P + ".dds",
          P + "_shadowed.ktx2", P + "_shadowed_array.ktx2", P + "_shadowed.dds", P + "_attenuation.ktx2",
          P + "_attenuation.dds", P + "_params.ktx2", P + ".exr",                P + "_report.json",
          P + "_residuals.exr", P + "_residuals.png"};
}

}  // namespace skybake::fog
