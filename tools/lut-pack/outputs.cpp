#include "outputs.h"

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "color/color.h"
#include "color/exr_color.h"
#include "io/yaml.h"
#include "lut/contact_sheet.h"
#include "lut/dds.h"
#include "lut/decoder.h"
#include "lut/inspection.h"

namespace skybake::luttool {

namespace {

// R, G, B (decoded, physical units) + the packing error and the clamp flags of each texel.
ExrImage InspectionImage(int width, int height, const lut::PackedTexture& t, const Provenance& prov) {
  ExrImage img = lut::PackedInspectionImage(
      width, height, t,
      "R, G, B: the packed texels as a shader reads them, divided by the scale (physical units, Linear Rec.2020); "
      "input_R/G/B: the values before packing; clamp_flags: 1 = a component above the format's largest value, "
      "2 = a negative component (outside Rec.2020), 4 = a denormal component (bit OR)");
  SetProvenance(img, prov);
  return img;
}

std::string Rows(const lut::LutSet& set) {
  std::string rows;
  for (const lut::SkyLutProduct& s : set.skies) rows += (rows.empty() ? "" : " ") + s.name;
  return rows;
}

dds::Texture Dds(const lut::PackedTexture& t, bool volume) {
  dds::Texture d;
  d.width = static_cast<uint32_t>(t.width);
  d.height = static_cast<uint32_t>(t.height);
  d.depth = volume ? static_cast<uint32_t>(t.depth) : 0;
  d.data = t.bytes;
  return d;
}

}  // namespace

std::string DisplayShaderJson(const ColorConfig& config) {
  constexpr const char* kFunction = "OCIODisplay";
  DisplayView view;  // the sRGB display, Un-tone-mapped view (the PNG previews' default)
  nlohmann::ordered_json j;
  j["source"] = "lut-pack: OCIO's GPU shader (GpuShaderDesc, GLSL ES 3.0) of the config's display view; docs/runtime.md";
  j["ocio_config"] = config.path().filename().string();
  j["ocio_config_cache_id"] = config.cache_id();
  j["input_colorspace"] = ocio_names::kLinearRec2020;
  j["display"] = view.display;
  j["view"] = view.view;
  j["function"] = kFunction;
  j["usage"] = "display = OCIODisplay(vec4(radiance_cd_m2 * exposure, 1)).rgb, exposure = 1 / (the luminance in cd/m^2 shown as "
               "white); the view is not tone-mapped (display-linear 1 = white)";
  j["glsl"] = config.DisplayShaderGlslEs3(ocio_names::kLinearRec2020, view, kFunction);
  // Y of Linear Rec.2020 primaries through OCIO (the conversion the packer's statistics use).
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  nlohmann::ordered_json y = nlohmann::ordered_json::array();
  for (int c = 0; c < 3; ++c) {
    std::array<float, 3> e{0.f, 0.f, 0.f};
    e[c] = 1.f;
    y.push_back(to_xyz.Apply(e)[1]);
  }
  j["luminance_from_rgb"] = y;
  return j.dump(2) + "\n";
}

std::map<std::string, std::string> EncodeLutSet(const lut::LutSet& set, const Provenance& prov,
                                                const std::map<std::string, Provenance>& sky_prov, const ColorConfig& config,
                                                const Font& font) {
  std::map<std::string, std::string> out;
  std::vector<lut::SkyLutDecoder> decoders;  // of the packed 3D textures, for the contact sheet
  decoders.reserve(set.skies.size());
  for (const lut::SkyLutProduct& s : set.skies) {
    const Provenance& sp = sky_prov.at(s.name);
    const std::string base = "sky_" + s.name;
    const ktx2::Texture volume = lut::SkyKtx2(set, s, false, sp);
    out[base + ".ktx2"] = ktx2::EncodeKtx2(volume);
    decoders.push_back(lut::SkyLutDecoder::FromKtx2(volume, base + ".ktx2"));
    out[base + "_array.ktx2"] = ktx2::EncodeKtx2(lut::SkyKtx2(set, s, true, sp));
    out[base + ".dds"] = dds::EncodeDds(Dds(s.sky, true));
    ExrImage img = InspectionImage(s.sky.width, s.sky.height * s.sky.depth, s.sky, sp);
    std::string zen;
    for (double z : s.render->slice_zenith_deg) zen += (zen.empty() ? "" : " ") + FormatExact(z);
    img.strings["skybake.layout"] = fmt::format("{} slices of {}x{} stacked top to bottom (slice k in rows {}k .. {}k + {})",
                                                s.sky.depth, s.sky.width, s.sky.height, s.sky.height, s.sky.height,
                                                s.sky.height - 1);
    img.strings["skybake.slice_zenith_deg"] = zen;
    img.strings["skybake.mapping"] = s.render->sphere.Describe();
    img.strings["skybake.basis_sky"] = s.name;
    out[base + ".exr"] = EncodeExr(img);
  }
  struct Other {
    const char* name;
    const lut::PackedTexture* t;
    std::string quantity, axis;
  };
  const std::vector<Other> others = {
      {"transmittance", &set.transmittance,
       "transmittance from the observer to space for sunlight, per Linear Rec.2020 channel: [E0 T]_c / [E0]_c (1)",
       "view zenith angle 0..180 deg, texel i at i deg: u = (i + 1/2)/181; rows: " + Rows(set)},
      {"sun", &set.sun, "direct sun illuminance at normal incidence (lux, Linear Rec.2020), times skybake.scale",
       "the sky LUT's slices: u = (s + 1/2)/N for slice coordinate s; rows: " + Rows(set)},
      {"ambient", &set.ambient, "sky illuminance on a horizontal surface without the sun disk (lux, Linear Rec.2020), times skybake.scale",
       "the sky LUT's slices: u = (s + 1/2)/N for slice coordinate s; rows: " + Rows(set)},
  };
  std::vector<ExrPart> parts;
  for (const Other& o : others) {
    out[std::string(o.name) + ".ktx2"] = ktx2::EncodeKtx2(lut::TableKtx2(set, *o.t, o.quantity, o.axis, prov));
    out[std::string(o.name) + ".dds"] = dds::EncodeDds(Dds(*o.t, false));
    ExrImage img = InspectionImage(o.t->width, o.t->height, *o.t, prov);
    img.strings["skybake.quantity"] = o.quantity;
    img.strings["skybake.axis_u"] = o.axis;
    parts.push_back({o.name, std::move(img)});
  }
  out["other_luts.exr"] = EncodeExrParts(parts);
  std::vector<lut::ContactSheetSky> sheet;
  for (size_t i = 0; i < set.skies.size(); ++i) sheet.push_back({set.skies[i].name, &decoders[i]});
  out["contact_sheet.png"] = lut::RenderContactSheet(sheet, set.skies[0].render->time_mapping_name, config, font).png;
  return out;
}

}  // namespace skybake::luttool
