#include "report.h"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <numbers>

#include "lut/r11g11b10.h"
#include "skybake/version.h"

namespace skybake::luttool {

namespace {

using Json = nlohmann::ordered_json;
constexpr double kDeg = std::numbers::pi / 180.0;

// A YAML node as JSON: mappings, sequences, and scalars as numbers where the whole scalar is one.
Json YamlToJson(const YAML::Node& n) {
  if (n.IsMap()) {
    Json j = Json::object();
    for (const auto& kv : n) j[kv.first.as<std::string>()] = YamlToJson(kv.second);
    return j;
  }
  if (n.IsSequence()) {
    Json j = Json::array();
    for (const auto& e : n) j.push_back(YamlToJson(e));
    return j;
  }
  const std::string t = n.as<std::string>();
  double v = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (!t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size()) return v;
  return t;
}

// The render's automatic quality choice (sky-render choose), or null for a quality given by hand.
Json QualityChoiceJson(const std::string& flow) {
  if (flow.empty()) return nullptr;
  try {
    return YamlToJson(YAML::Load(flow));
  } catch (const YAML::Exception&) {
    return flow;  // the provenance as written, when it is no YAML mapping
  }
}

Json StatsJson(const lut::PackStats& s) {
  Json j;
  j["texels"] = s.texels;
  j["clamped_above_max"] = {{"texels", s.clamped_high}, {"largest_component_before_clamping", s.max_value}};
  j["negative_rec2020"] = {{"texels", s.negative_texels}, {"worst_negative_component_over_Y", s.worst_negative_fraction}};
  j["denormal_texels"] = s.denormal_texels;
  j["zero_luminance_texels"] = s.zero_luminance;
  j["measured_texels"] = s.measured;
  j["luminance_relative_error"] = {
      {"rms", s.y_rel_rms},
      {"p50", s.y_rel_percentiles[0]},
      {"p90", s.y_rel_percentiles[1]},
      {"p99", s.y_rel_percentiles[2]},
      {"p99.9", s.y_rel_percentiles[3]},
      {"max", s.y_rel_max},
      {"histogram_percent", {{"[0, 0.1)", s.y_rel_histogram[0]}, {"[0.1, 0.2)", s.y_rel_histogram[1]},
                             {"[0.2, 0.4)", s.y_rel_histogram[2]}, {"[0.4, 0.6)", s.y_rel_histogram[3]},
                             {"[0.6, 1)", s.y_rel_histogram[4]}, {">= 1", s.y_rel_histogram[5]}}},
  };
  j["channel_relative_error_max"] = {{"R", s.channel_rel_max[0]}, {"G", s.channel_rel_max[1]}, {"B", s.channel_rel_max[2]}};
  j["channel_relative_error_bound"] = {{"R", std::ldexp(1.0, -7)}, {"G", std::ldexp(1.0, -7)}, {"B", std::ldexp(1.0, -6)}};
  return j;
}

// Where in the sky the clamped texels and the worst packing error of a sky LUT are.
Json SkyWhereJson(const lut::SkyLutProduct& p) {
  const lut::SkyRender& r = *p.render;
  const lut::PackedTexture& t = p.sky;
  const size_t per_slice = static_cast<size_t>(t.width) * t.height;
  auto angles = [&](size_t i) {
    const size_t k = i / per_slice, xy = i % per_slice;
    const double ts = r.slice_zenith_deg[k] * kDeg;
    const std::array<double, 3> d =
        r.sphere.Direction((static_cast<double>(xy % t.width) + 0.5) / t.width, (static_cast<double>(xy / t.width) + 0.5) / t.height, ts);
    const double sun_angle = std::acos(std::clamp(d[0] * std::sin(ts) + d[2] * std::cos(ts), -1.0, 1.0)) / kDeg;
    return Json{{"slice", k}, {"sun_zenith_deg", r.slice_zenith_deg[k]}, {"x", xy % t.width}, {"y", xy / t.width},
                {"view_zenith_deg", std::acos(std::clamp(d[2], -1.0, 1.0)) / kDeg},
                {"azimuth_from_sun_deg", std::atan2(d[1], d[0]) / kDeg}, {"angle_from_sun_deg", sun_angle}};
  };
  Json j;
  double widest = -1.0;
  Json widest_at;
  for (size_t i = 0; i < t.clamp_flags.size(); ++i) {
    if (!(t.clamp_flags[i] & 1)) continue;
    Json a = angles(i);
    if (a["angle_from_sun_deg"].get<double>() > widest) {
      widest = a["angle_from_sun_deg"].get<double>();
      widest_at = a;
    }
  }
  j["clamped_texel_farthest_from_the_sun"] = widest < 0.0 ? Json(nullptr) : widest_at;
  j["worst_packing_error_at"] = t.stats.measured ? angles(t.stats.worst_texel) : Json(nullptr);
  return j;
}

}  // namespace

std::string PackReportJson(const lut::LutSet& set, const ReportContext& ctx) {
  const lut::SkyRender& r0 = *set.skies[0].render;
  Json j;
  j["tool"] = "lut-pack";
  j["version"] = kVersion;
  j["format"] = "R11G11B10F: VK_FORMAT_B10G11R11_UFLOAT_PACK32 (122) in KTX2, DXGI_FORMAT_R11G11B10_FLOAT (26) in DDS; "
                "round to nearest even, negatives and NaN -> 0, above the largest finite value (65024 R/G, 64512 B) -> "
                "that value";
  j["colorspace"] = "Linear Rec.2020 (OCIO, " + ctx.ocio_config + ")";
  j["time_mapping"] = {{"name", r0.time_mapping_name},
                       {"description", r0.time.Describe()},
                       {"observer_radius_m", r0.time.observer_radius_m},
                       {"top_radius_m", r0.time.top_radius_m},
                       {"slice_zenith_deg", r0.slice_zenith_deg}};
  j["sphere_mapping"] = {{"description", r0.sphere.Describe()},
                         {"threshold_elevation_deg", r0.sphere.threshold_elevation_deg}};
  j["night"] = {{"rule", "below the last slice the sky moves linearly to the uniform radiance night_rgb, reached at "
                         "night_end_zenith_deg"},
                {"night_end_zenith_deg", set.options.night_end_zenith_deg}};
  j["budget"] = {{"sky_lut_texel_bytes", ctx.sky_texel_bytes},
                 {"sky_lut_MiB", static_cast<double>(ctx.sky_texel_bytes) / (1024.0 * 1024.0)},
                 {"limit_bytes", ctx.budget_bytes},
                 {"within", static_cast<double>(ctx.sky_texel_bytes) <= ctx.budget_bytes}};
  Json skies = Json::array();
  for (const lut::SkyLutProduct& p : set.skies) {
    const lut::SkyRender& r = *p.render;
    Json s;
    s["name"] = p.name;
    s["render"] = r.path;
    s["method"] = r.method;
    s["quality_choice"] = QualityChoiceJson(r.quality_choice);
    s["size"] = {{"width", r.width}, {"height", r.height}, {"slices", r.time.slices()}};
    s["texel_bytes"] = p.sky.bytes.size();
    s["scale"] = p.sky.scale;
    s["night_rgb_cd_m2"] = p.night_rgb;
    s["files"] = {{"ktx2_3d", "sky_" + p.name + ".ktx2"}, {"ktx2_array", "sky_" + p.name + "_array.ktx2"},
                  {"dds_3d", "sky_" + p.name + ".dds"}, {"exr", "sky_" + p.name + ".exr"}};
    s["pack"] = StatsJson(p.sky.stats);
    s["where"] = SkyWhereJson(p);
    skies.push_back(s);
  }
  j["skies"] = skies;
  auto table = [&](const lut::PackedTexture& t, const std::string& file, const std::string& unit, const std::string& axis) {
    return Json{{"file", file},         {"width", t.width}, {"rows", t.height}, {"axis_u", axis},
                {"unit", unit},         {"scale", t.scale}, {"texel_bytes", t.bytes.size()},
                {"pack", StatsJson(t.stats)}};
  };
  j["other_luts"] = {
      {"rows", [&] {
         Json a = Json::array();
         for (const lut::SkyLutProduct& p : set.skies) a.push_back(p.name);
         return a;
       }()},
      {"transmittance", table(set.transmittance, "transmittance.ktx2", "1",
                              "view zenith angle 0..180 deg, texel i at i deg (u = (i + 1/2)/181)")},
      {"sun", table(set.sun, "sun.ktx2", "lux (normal incidence)", "the sky LUT's slices (u = (s + 1/2)/N)")},
      {"ambient", table(set.ambient, "ambient.ktx2", "lux (horizontal surface)", "the sky LUT's slices (u = (s + 1/2)/N)")},
  };
  Json files = Json::object();
  size_t total = 0;
  for (const auto& [name, bytes] : ctx.file_bytes) {
    files[name] = bytes;
    total += bytes;
  }
  j["files_bytes"] = files;
  j["files_total_bytes"] = total;
  return j.dump(2) + "\n";
}

std::string CheckReportJson(const lut::CheckResult& r, const std::string& luts) {
  auto where = [](const lut::CheckWhere& w) {
    return Json{{"relative_error", w.error},     {"view_zenith_deg", w.view_zenith_deg}, {"azimuth_from_sun_deg", w.azimuth_deg},
                {"angle_from_sun_deg", w.sun_angle_deg}, {"Y_direct_cd_m2", w.y_direct}, {"Y_decoded_cd_m2", w.y_decoded}};
  };
  Json j;
  j["tool"] = "lut-pack check";
  j["luts"] = luts;
  j["direct"] = r.direct;
  j["direct_mapping"] = r.direct_mapping;
  j["metric"] = "relative luminance error (Y_decoded - Y_direct) / Y_direct, RMS weighted by texel solid angle";
  j["sun_cone_deg"] = r.sun_cone_deg;
  j["rms_upper_all"] = r.rms_upper_all;
  j["rms_upper_all_outside_sun_cone"] = r.rms_upper_all_outside_cone;
  j["worst_slice_rms_upper"] = r.worst_slice_rms_upper;
  Json slices = Json::array();
  for (const lut::CheckSlice& s : r.slices) {
    slices.push_back(Json{{"sun_zenith_deg", s.sun_zenith_deg},
                          {"slice_coordinate", s.slice_coordinate},
                          {"rms_upper", s.rms_upper},
                          {"rms_upper_outside_sun_cone", s.rms_upper_outside_cone},
                          {"mean_upper", s.mean_upper},
                          {"rms_lower", s.rms_lower},
                          {"rms_lower_outside_sun_cone", s.rms_lower_outside_cone},
                          {"max_upper", where(s.max_upper)},
                          {"max_upper_outside_sun_cone", where(s.max_upper_outside_cone)},
                          {"max_lower", where(s.max_lower)},
                          {"texels", s.texels},
                          {"skipped_zero_luminance", s.skipped}});
  }
  j["slices"] = slices;
  return j.dump(2) + "\n";
}

}  // namespace skybake::luttool
