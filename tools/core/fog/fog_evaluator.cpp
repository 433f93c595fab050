#include "fog/fog_evaluator.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "io/error.h"
#include "io/fileio.h"
#include "lut/r11g11b10.h"

namespace fs = std::filesystem;

namespace skybake::fog {

std::array<double, 3> ClampToHorizon(const std::array<double, 3>& d) {
  if (d[2] >= 0.0) return d;
  const double h = std::hypot(d[0], d[1]);
  if (!(h > 0.0)) return {1.0, 0.0, 0.0};
  return {d[0] / h, d[1] / h, 0.0};
}

AttenuationLut::AttenuationLut(int width, int height, std::vector<float> rgb) : w_(width), h_(height), rgb_(std::move(rgb)) {
  SKYBAKE_CHECK(w_ >= 2 && h_ >= 2);
  SKYBAKE_CHECK_EQ(rgb_.size(), static_cast<size_t>(w_) * h_ * 3);
}

AttenuationLut AttenuationLut::FromKtx2(const ktx2::Texture& t, const std::string& name) {
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, msg); };
  if (t.format.vk_format != ktx2::VkFormat::kB10G11R11UfloatPack32) fail("not a B10G11R11_UFLOAT_PACK32 texture");
  if (t.width < 2 || t.height < 2 || t.depth > 1 || t.layers > 1) fail("the attenuation LUT must be a 2D texture of at least 2x2");
  const std::string s = t.GetString("skybake.scale");
  double scale = 0.0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), scale);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || !(scale > 0.0)) {
    fail("KTX2 key 'skybake.scale' must be a positive number, got \"" + s + "\"");
  }
  std::vector<float> rgb = r11g11b10::UnpackTexels(t.data);
  if (rgb.size() != static_cast<size_t>(t.width) * t.height * 3) fail("texel data of the wrong size");
  for (float& v : rgb) v = static_cast<float>(v / scale);
  return AttenuationLut(static_cast<int>(t.width), static_cast<int>(t.height), std::move(rgb));
}

std::array<double, 3> AttenuationLut::Sample(double u, double v) const {
  const double x = std::clamp(u, 0.0, 1.0) * (w_ - 1), y = std::clamp(v, 0.0, 1.0) * (h_ - 1);
  const int x0 = std::min(static_cast<int>(x), w_ - 2), y0 = std::min(static_cast<int>(y), h_ - 2);
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xx, int yy, int c) { return static_cast<double>(rgb_[(static_cast<size_t>(yy) * w_ + xx) * 3 + c]); };
  std::array<double, 3> out;
  for (int c = 0; c < 3; ++c) {
    out[c] = (1 - fy) * ((1 - fx) * at(x0, y0, c) + fx * at(x0 + 1, y0, c)) +
             fy * ((1 - fx) * at(x0, y0 + 1, c) + fx * at(x0 + 1, y0 + 1, c));
  }
  return out;
}

FogEvaluator::FogEvaluator(FogParams params, lut::SkyLutDecoder fog, lut::SkyLutDecoder shadowed, AttenuationLut attenuation)
    : params_(std::move(params)), geo_(params_.geometry()), fog_(std::move(fog)), shadowed_(std::move(shadowed)),
      att_(std::move(attenuation)) {
  SKYBAKE_CHECK(params_.slices.empty() || static_cast<int>(params_.slices.size()) == fog_.slices());
  for (size_t j = 1; j < params_.node_v.size(); ++j) SKYBAKE_CHECK(params_.node_v[j] > params_.node_v[j - 1]);
  for (const FogParams::Slice& s : params_.slices) {
    SKYBAKE_CHECK_EQ(s.a_nodes.size(), params_.node_v.size());
    SKYBAKE_CHECK_EQ(s.a_shadowed_nodes.size(), params_.node_v.size());
  }
}

FogParams::Slice FogEvaluator::ParamsAt(double sun_zenith_rad, double mu) const {
  if (params_.slices.empty()) return {params_.a, params_.p, params_.a_shadowed, params_.p_shadowed, {}, {}};
  // One slice's parameters at mu: a linear in v between the elevation nodes.
  const std::vector<double>& nv = params_.node_v;
  const double v = AttenuationV(mu);
  size_t j = 0;
  double w = 0.0;
  if (nv.size() > 1) {
    while (j + 2 < nv.size() && v > nv[j + 1]) ++j;
    w = std::clamp((v - nv[j]) / (nv[j + 1] - nv[j]), 0.0, 1.0);
  }
  auto at = [&](const FogParams::Slice& s) {
    FogParams::Slice o{s.a, s.p, s.a_shadowed, s.p_shadowed, {}, {}};
    if (nv.empty()) return o;
    for (size_t c = 0; c < 3; ++c) {
      const size_t j1 = std::min(j + 1, nv.size() - 1);
      o.a[c] = (1 - w) * s.a_nodes[j][c] + w * s.a_nodes[j1][c];
      o.a_shadowed[c] = (1 - w) * s.a_shadowed_nodes[j][c] + w * s.a_shadowed_nodes[j1][c];
    }
    return o;
  };
  const auto [i, t] = fog_.SliceBlend(sun_zenith_rad);
  const FogParams::Slice lo = at(params_.slices[static_cast<size_t>(i)]);
  if (t <= 0.0) return lo;
  const FogParams::Slice hi = at(params_.slices[static_cast<size_t>(i) + 1]);
  FogParams::Slice out;
  for (size_t c = 0; c < 3; ++c) {
    out.a[c] = (1 - t) * lo.a[c] + t * hi.a[c];
    out.p[c] = (1 - t) * lo.p[c] + t * hi.p[c];
    out.a_shadowed[c] = (1 - t) * lo.a_shadowed[c] + t * hi.a_shadowed[c];
    out.p_shadowed[c] = (1 - t) * lo.p_shadowed[c] + t * hi.p_shadowed[c];
  }
  return out;
}

std::array<double, 3> FogEvaluator::LutRadiance(const std::array<double, 3>& d, double sun_zenith_rad, bool shadowed) const {
  // Read at d itself, also below the horizon: those texels hold the horizon's value (the render
  // clamps their directions), so the LUT already answers for them, and every texel centre reads
  // back its own texel (clamping d first would read between the rows around the horizon row).
  return (shadowed ? shadowed_ : fog_).Radiance(d, sun_zenith_rad);
}

FogValue FogEvaluator::Evaluate(const std::array<double, 3>& d, double depth_m, double sun_zenith_rad, double occlusion) const {
  FogValue v;
  const double mu = d[2];
  v.x = geo_.NormalisedDepth(depth_m, mu);
  v.theta = geo_.Theta(params_.angle, mu);
  const double o = std::clamp(std::isfinite(occlusion) ? occlusion : 0.0, 0.0, 1.0);
  if (v.x > 0.0) {
    const std::array<double, 3> L = LutRadiance(d, sun_zenith_rad, false);
    std::array<double, 3> S{0, 0, 0};
    if (o > 0.0) S = LutRadiance(d, sun_zenith_rad, true);
    const FogParams::Slice q = ParamsAt(sun_zenith_rad, mu);
    for (size_t c = 0; c < 3; ++c) {
      const double F = DepthFactor(v.x, DepthExponent(q.a[c], q.p[c], v.theta));
      const double Fs = DepthFactor(v.x, DepthExponent(q.a_shadowed[c], q.p_shadowed[c], v.theta));
      v.inscattered[c] = (1.0 - o) * L[c] * F + o * S[c] * Fs;
    }
  }
  v.transmittance = att_.Sample(AttenuationU(v.x), AttenuationV(mu));
  return v;
}

// ------------------------------------------------------------------------------------- loading

namespace {

using Json = nlohmann::json;

int LineOfByte(const std::string& text, size_t byte) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(std::min(byte, text.size())), '\n'));
}

}  // namespace

FogEvaluator FogEvaluator::Load(const fs::path& path, std::vector<fs::path>* files_read) {
  const std::string name = path.string();
  const std::string text = ReadFileBytes(path);
  if (files_read) files_read->push_back(path);
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::parse_error& e) {
    std::string msg = e.what();
    const size_t at = msg.find("]: ");
    throw InputError(FileLoc{name, LineOfByte(text, e.byte > 0 ? e.byte - 1 : 0)},
                     "not valid JSON: " + (at == std::string::npos ? msg : msg.substr(at + 3)));
  }
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, msg); };
  auto number = [&](const Json& o, const char* key, const std::string& where) {
    if (!o.is_object() || !o.contains(key) || !o[key].is_number()) fail("'" + where + key + "' must be a number");
    const double v = o[key].get<double>();
    if (!std::isfinite(v)) fail("'" + where + key + "' must be finite");
    return v;
  };
  auto triple = [&](const Json& o, const char* key, const std::string& where, bool positive) {
    if (!o.is_object() || !o.contains(key) || !o[key].is_array() || o[key].size() != 3) {
      fail("'" + where + key + "' must be a list of 3 numbers (R, G, B)");
    }
    std::array<double, 3> v{};
    for (size_t c = 0; c < 3; ++c) {
      if (!o[key][c].is_number()) fail("'" + where + key + "' must be a list of 3 numbers (R, G, B)");
      v[c] = o[key][c].get<double>();
      if (!std::isfinite(v[c]) || (positive && !(v[c] > 0.0))) fail("'" + where + key + "' must hold finite" + (positive ? " positive" : "") + " numbers");
    }
    return v;
  };
  if (!j.is_object() || !j.contains("model") || !j["model"].is_object()) fail("no 'model' section: not a fog-fit parameter file");
  const Json& m = j["model"];
  FogParams p;
  if (j.contains("basis_sky") && j["basis_sky"].is_string()) p.basis_sky = j["basis_sky"].get<std::string>();
  if (!m.contains("angle") || !m["angle"].is_string() || !ParseAngleDefinition(m["angle"].get<std::string>())) {
    fail("'model.angle' must be \"path\" or \"elevation\"");
  }
  p.angle = *ParseAngleDefinition(m["angle"].get<std::string>());
  p.planet_radius_m = number(m, "planet_radius_m", "model.");
  p.observer_altitude_m = number(m, "observer_altitude_m", "model.");
  p.cut_altitude_m = number(m, "cut_altitude_m", "model.");
  try {
    (void)p.geometry();
  } catch (const UsageError& e) {
    fail(e.what());
  }
  if (!m.contains("fog") || !m.contains("shadowed")) fail("'model' needs the 'fog' and 'shadowed' parameters");
  p.a = triple(m["fog"], "a", "model.fog.", true);
  p.p = triple(m["fog"], "p", "model.fog.", false);
  p.a_shadowed = triple(m["shadowed"], "a", "model.shadowed.", true);
  p.p_shadowed = triple(m["shadowed"], "p", "model.shadowed.", false);
  if (m.contains("per_slice")) {
    // One row of (R, G, B) per slice for each of fog.a, fog.p, shadowed.a, shadowed.p.
    const Json& ps = m["per_slice"];
    auto rows = [&](const char* prod, const char* key, bool positive) {
      const std::string where = std::string("model.per_slice.") + prod + "." + key;
      if (!ps.is_object() || !ps.contains(prod) || !ps[prod].is_object() || !ps[prod].contains(key) || !ps[prod][key].is_array()) {
        fail("'" + where + "' must be a list of [R, G, B] per slice");
      }
      std::vector<std::array<double, 3>> out;
      for (const Json& r : ps[prod][key]) {
        if (!r.is_array() || r.size() != 3) fail("'" + where + "' must be a list of [R, G, B] per slice");
        std::array<double, 3> v{};
        for (size_t c = 0; c < 3; ++c) {
          if (!r[c].is_number()) fail("'" + where + "' must be a list of [R, G, B] per slice");
          v[c] = r[c].get<double>();
          if (!std::isfinite(v[c]) || (positive && !(v[c] > 0.0))) {
            fail("'" + where + "' must hold finite" + (positive ? " positive" : "") + " numbers");
          }
        }
        out.push_back(v);
      }
      return out;
    };
    const auto fa = rows("fog", "a", true), fp = rows("fog", "p", false), sa = rows("shadowed", "a", true),
               sp = rows("shadowed", "p", false);
    if (fa.empty() || fp.size() != fa.size() || sa.size() != fa.size() || sp.size() != fa.size()) {
      fail("'model.per_slice': fog.a, fog.p, shadowed.a and shadowed.p need one row per slice each");
    }
    for (size_t k = 0; k < fa.size(); ++k) p.slices.push_back({fa[k], fp[k], sa[k], sp[k], {}, {}});
    if (ps.contains("elevation_nodes")) {
      // a per slice and elevation node: [slice][node][R, G, B] for fog and shadowed fog.
      const Json& en = ps["elevation_nodes"];
      if (!en.is_object() || !en.contains("v") || !en["v"].is_array() || en["v"].empty()) {
        fail("'model.per_slice.elevation_nodes.v' must be a list of numbers");
      }
      for (const Json& v : en["v"]) {
        if (!v.is_number() || !(v.get<double>() >= 0.0 && v.get<double>() <= 1.0)) fail("'model.per_slice.elevation_nodes.v' must hold numbers in [0, 1]");
        if (!p.node_v.empty() && !(v.get<double>() > p.node_v.back())) fail("'model.per_slice.elevation_nodes.v' must be increasing");
        p.node_v.push_back(v.get<double>());
      }
      for (const char* prod : {"fog", "shadowed"}) {
        const std::string where = std::string("model.per_slice.elevation_nodes.") + prod + ".a";
        if (!en.contains(prod) || !en[prod].is_object() || !en[prod].contains("a") || !en[prod]["a"].is_array() ||
            en[prod]["a"].size() != p.slices.size()) {
          fail("'" + where + "' must hold one list of [R, G, B] per node for each slice");
        }
        for (size_t k = 0; k < p.slices.size(); ++k) {
          const Json& node_rows = en[prod]["a"][k];
          if (!node_rows.is_array() || node_rows.size() != p.node_v.size()) fail("'" + where + "' must hold one [R, G, B] per node for each slice");
          for (const Json& r : node_rows) {
            if (!r.is_array() || r.size() != 3) fail("'" + where + "' must hold [R, G, B] rows");
            std::array<double, 3> v{};
            for (size_t c = 0; c < 3; ++c) {
              if (!r[c].is_number() || !std::isfinite(r[c].get<double>()) || !(r[c].get<double>() > 0.0)) {
                fail("'" + where + "' must hold finite positive numbers");
              }
              v[c] = r[c].get<double>();
            }
            (std::string(prod) == "fog" ? p.slices[k].a_nodes : p.slices[k].a_shadowed_nodes).push_back(v);
          }
        }
      }
    }
  }
  if (!j.contains("files") || !j["files"].is_object()) fail("no 'files' section");
  auto file = [&](const char* key) {
    if (!j["files"].contains(key) || !j["files"][key].is_string()) fail(std::string("'files.") + key + "' must be a file name");
    const fs::path f = path.parent_path() / j["files"][key].get<std::string>();
    if (files_read) files_read->push_back(f);
    return f;
  };
  const fs::path fog_path = file("fog"), sh_path = file("shadowed"), att_path = file("attenuation");
  lut::SkyLutDecoder fog = lut::SkyLutDecoder::FromKtx2(ktx2::ReadKtx2(fog_path), fog_path.string());
  lut::SkyLutDecoder sh = lut::SkyLutDecoder::FromKtx2(ktx2::ReadKtx2(sh_path), sh_path.string());
  AttenuationLut att = AttenuationLut::FromKtx2(ktx2::ReadKtx2(att_path), att_path.string());
  if (!p.slices.empty() && static_cast<int>(p.slices.size()) != fog.slices()) {
    fail(fmt::format("'model.per_slice' has {} slices, but the fog LUT {} has {}", p.slices.size(), fog_path.string(), fog.slices()));
  }
  if (sh.slices() != fog.slices()) fail("the fog and shadowed fog LUTs have different slice counts");
  return FogEvaluator(std::move(p), std::move(fog), std::move(sh), std::move(att));
}

}  // namespace skybake::fog
