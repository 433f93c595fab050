// Writing and reading the multi-part EXR of a reference fog render (fog/fog_render.h; docs/fog.md,
// "Reference renders"), whole or one shard of it (fog/fog_shard.h).
#include "fog/fog_render.h"

#include <cmath>

#include <fmt/format.h>

#include "color/color.h"
#include "fog/fog_shard.h"
#include "io/error.h"
#include "io/exr_attributes.h"
#include "io/yaml.h"

namespace fs = std::filesystem;

namespace skybake::fog {

namespace {

void SetFogAttributes(ExrImage& img, const FogRender& r) {
  img.strings["skybake.fog.atmosphere"] = r.atmosphere;
  img.strings["skybake.fog.method"] = r.method;
  img.strings["skybake.observer"] = r.observer;
  img.doubles["skybake.fog.planet_radius_m"] = r.planet_radius_m;
  img.doubles["skybake.fog.top_altitude_m"] = r.top_altitude_m;
  img.doubles["skybake.fog.observer_altitude_m"] = r.observer_altitude_m;
  img.doubles["skybake.fog.cut_altitude_m"] = r.cut_altitude_m;
}

std::string Segment(const FogRender& r) {
  return fmt::format("the medium on the view ray below {} m of altitude (the cut) and, in depth tables, closer than "
                     "the depth; lit by the full atmosphere; no ground surface (transport/view_segment.h)",
                     FormatExact(r.cut_altitude_m));
}

}  // namespace

void WriteFogRender(const Scene& scene, const FogRenderOptions& o, const FogRender& r, const fs::path& path,
                    const std::string& tool) {
  Provenance prov;
  prov.tool = tool;
  std::string az, sz;
  for (double a : r.azimuth_deg) az += (az.empty() ? "" : ",") + FormatExact(a);
  for (const FogDepthTable& t : r.tables) sz += (sz.empty() ? "" : ",") + FormatExact(t.sun_zenith_deg);
  prov.parameters = fmt::format(
      "subcommand: fog\ncut_altitude_m: {}\nobserver_altitude_m: {}\nlut_size: {}x{}\nlut_texels: {}\ntime_mapping: {}\n"
      "sun_zenith_deg: [{}]\nelevations: {}\nazimuth_deg: [{}]\ndepths: {}\nattenuation_size: {}x{}\n",
      FormatExact(r.cut_altitude_m), FormatExact(r.observer_altitude_m), r.lut_width, r.lut_height,
      gt7::TexelGridName(r.texel_grid), r.time_mapping_name, sz, r.elevation_deg.size(), az, r.depth_x.size(), r.attenuation_width, r.attenuation_height) +
                    r.method_description + scene.parameters;
  for (const fs::path& f : scene.files_read) prov.AddInput(f);
  (void)o;

  std::vector<ExrPart> parts;
  const gt7::Gt7SkyMapping mapping = r.mapping();
  const size_t texels = static_cast<size_t>(r.lut_width) * r.lut_height;
  const FogShardRange own = FogShardRangeOf(r.shard, r.slice_zenith_deg.size(), r.tables.size());
  for (size_t k = own.slice_begin; k < own.slice_end; ++k) {
    ExrImage img;
    img.Resize(r.lut_width, r.lut_height, {"R", "G", "B", "shadowed_R", "shadowed_G", "shadowed_B", "Y_stderr"});
    for (size_t t = 0; t < texels; ++t) {
      for (int c = 0; c < 3; ++c) {
        img.pixels[t * 7 + c] = r.slice_xyz[k][t * 3 + c];
        img.pixels[t * 7 + 3 + c] = r.slice_shadowed_xyz[k][t * 3 + c];
      }
      img.pixels[t * 7 + 6] = r.slice_y_stderr[k][t];
    }
    img.chromaticities = XyzChromaticities();
    img.strings["skybake.quantity"] =
        "fog of the whole low-atmosphere segment (normalised depth x = 1): in-scattered radiance, R, G, B = X, Y, Z "
        "(cd/m^2, CIE-XYZ-D65); shadowed_*: the same without the single-scattered sun; Y_stderr: the fog's standard "
        "error (path). Directions below the horizon are clamped to it. Segment: " + Segment(r);
    img.strings["skybake.mapping"] = mapping.Describe();
    img.doubles["skybake.sun_zenith_deg"] = r.slice_zenith_deg[k];
    img.doubles["skybake.observer_altitude_m"] = r.observer_altitude_m;
    img.strings["skybake.time_mapping"] = r.time_mapping_name;
    img.strings["skybake.time_mapping.description"] = r.time.Describe();
    img.doubles["skybake.time_mapping.observer_radius_m"] = r.time.observer_radius_m;
    img.doubles["skybake.time_mapping.top_radius_m"] = r.time.top_radius_m;
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({FogSlicePartName(k, r.slice_zenith_deg[k]), std::move(img)});
  }
  const ExrAxis depth_axis{"depth_x", "1", "normalised depth x = d / D: (j/n)^3, j = 1..n (D: distance to the cut sphere)",
                           r.depth_x};
  const ExrAxis elevation_axis{"elevation", "deg", "view elevation above the horizon: 90 (i/(m-1))^2", r.elevation_deg};
  for (size_t ti = own.table_begin; ti < own.table_end; ++ti) {
    const FogDepthTable& t = r.tables[ti];
    ExrTable tab;
    tab.axes = {depth_axis, {"azimuth", "deg", "view azimuth from the sun (0: towards the sun's azimuth)", r.azimuth_deg},
                elevation_axis};
    tab.channels = {"X", "Y", "Z", "shadowed_X", "shadowed_Y", "shadowed_Z", "Y_stderr", "shadowed_Y_stderr"};
    tab.channel_units = {"cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2"};
    const size_t n = t.y_stderr.size();
    tab.values.reserve(n * 8);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) tab.values.push_back(t.xyz[i * 3 + c]);
      for (int c = 0; c < 3; ++c) tab.values.push_back(t.shadowed_xyz[i * 3 + c]);
      tab.values.push_back(t.y_stderr[i]);
      tab.values.push_back(t.shadowed_y_stderr[i]);
    }
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] =
        "fog between the observer and depth x D: in-scattered radiance X, Y, Z (cd/m^2, CIE-XYZ-D65); shadowed_*: "
        "without the single-scattered sun. Segment: " + Segment(r);
    img.doubles["skybake.sun_zenith_deg"] = t.sun_zenith_deg;
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({FogTablePartName(t.sun_zenith_deg), std::move(img)});
  }
  const ExrAxis wl_axis{"wavelength", "nm", "the model's wavelength grid", r.wavelength_nm};
  if (own.small_parts) {
    ExrTable tab;
    tab.axes = {wl_axis, depth_axis, elevation_axis};
    tab.channels = {"transmittance"};
    tab.channel_units = {"1"};
    tab.values = r.depth_transmittance;
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] = "transmittance from the observer to depth x D along the elevation";
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({"depth_transmittance", std::move(img)});
  }
  if (own.small_parts) {
    std::vector<double> u, v;
    for (int i = 0; i < r.attenuation_width; ++i) u.push_back(static_cast<double>(i) / (r.attenuation_width - 1));
    for (int i = 0; i < r.attenuation_height; ++i) v.push_back(static_cast<double>(i) / (r.attenuation_height - 1));
    ExrTable tab;
    tab.axes = {wl_axis, {"u", "1", "attenuation LUT node u = x^(1/3) (x: normalised depth)", u},
                {"v", "1", "attenuation LUT node v = (elevation / 90 deg)^(1/2)", v}};
    tab.channels = {"transmittance"};
    tab.channel_units = {"1"};
    tab.values = r.attenuation;
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] = "transmittance from the observer to depth x D at the attenuation LUT's nodes";
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({"attenuation", std::move(img)});
  }
  if (own.small_parts) {
    ExrTable tab;
    tab.axes = {wl_axis};
    tab.channels = {"e0"};
    tab.channel_units = {"W m^-2 nm^-1"};
    for (double e : r.sun_e0) tab.values.push_back(static_cast<float>(e));
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] = "extraterrestrial solar spectral irradiance on the grid (the model's sun)";
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({"sun", std::move(img)});
  }
  if (r.shard.count > 1) {
    ExrImage img = FogShardPart(r.shard, r.slice_zenith_deg.size(), r.tables.size());
    SetProvenance(img, prov);
    parts.push_back({kShardPart, std::move(img)});
  }
  WriteExrParts(path, parts);
}

// ------------------------------------------------------------------------------------- reading

FogRender ReadFogRender(const fs::path& path) {
  const std::string name = path.string();
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, msg); };
  const std::vector<ExrPart> parts = ReadExrParts(path);
  if (IsFogShard(parts)) fail("a shard of a fog render (sky-render fog --shard): join the shards with sky-render merge");
  FogRender r;
  r.path = name;
  const ExrImage& sun_img = FindPart(parts, "sun", name);
  auto need_d = [&](const ExrImage& img, const std::string& part, const std::string& key) {
    const double* v = FindDoubleAttribute(img, key);
    if (!v || !std::isfinite(*v)) fail("part '" + part + "' has no " + key + ": not a sky-render fog render");
    return *v;
  };
  auto need_s = [&](const ExrImage& img, const std::string& part, const std::string& key) {
    const std::string* v = FindStringAttribute(img, key);
    if (!v) fail("part '" + part + "' has no " + key + ": not a sky-render fog render");
    return *v;
  };
  r.atmosphere = need_s(sun_img, "sun", "skybake.fog.atmosphere");
  r.method = need_s(sun_img, "sun", "skybake.fog.method");
  r.observer = need_s(sun_img, "sun", "skybake.observer");
  r.planet_radius_m = need_d(sun_img, "sun", "skybake.fog.planet_radius_m");
  r.top_altitude_m = need_d(sun_img, "sun", "skybake.fog.top_altitude_m");
  r.observer_altitude_m = need_d(sun_img, "sun", "skybake.fog.observer_altitude_m");
  r.cut_altitude_m = need_d(sun_img, "sun", "skybake.fog.cut_altitude_m");
  try {
    (void)r.geometry();
  } catch (const UsageError& e) {
    fail(e.what());
  }
  if (const std::string* p = FindStringAttribute(sun_img, "skybake.parameters")) {
    const size_t at = p->find("method: ");
    if (at != std::string::npos) r.method_description = p->substr(at, p->find('\n', at) - at);
  }
  {
    const ExrTable t = ImageToTable(sun_img, name);
    if (t.axes.size() != 1 || t.axes[0].name != "wavelength" || t.ChannelIndex("e0") < 0) fail("part 'sun' is not a wavelength table of e0");
    r.wavelength_nm = t.axes[0].values;
    for (size_t i = 0; i < t.Count(); ++i) r.sun_e0.push_back(t.At(i, static_cast<size_t>(t.ChannelIndex("e0"))));
  }
  const size_t nw = r.wavelength_nm.size();
  auto same_fog = [&](const ExrImage& img, const std::string& part) {
    for (const char* key : {"skybake.fog.planet_radius_m", "skybake.fog.observer_altitude_m", "skybake.fog.cut_altitude_m"}) {
      const double* v = FindDoubleAttribute(img, key);
      if (!v || *v != *FindDoubleAttribute(sun_img, key)) fail("part '" + part + "' has another " + std::string(key) + " than part 'sun'");
    }
  };
  auto finite = [&](const std::vector<float>& v, const std::string& part) {
    for (float x : v) {
      if (!std::isfinite(x)) fail("part '" + part + "' has a value that is not finite");
    }
  };

  // Slices.
  std::vector<const ExrPart*> slices;
  for (const ExrPart& p : parts) {
    if (p.name.rfind("fog.", 0) != 0) continue;
    const int index = NumberedPartIndex(p.name, "fog.slice_");
    if (index != static_cast<int>(slices.size())) fail(fmt::format("part '{}' is out of order (expected slice {})", p.name, slices.size()));
    slices.push_back(&p);
  }
  if (slices.size() < 4) fail(fmt::format("{} fog LUT slices; a GT7 time mapping has at least 4", slices.size()));
  const ExrImage& first = slices[0]->image;
  r.lut_width = first.width;
  r.lut_height = first.height;
  r.time_mapping_name = need_s(first, slices[0]->name, "skybake.time_mapping");
  const std::optional<gt7::TimeMappingKind> kind = gt7::TimeMapping::ParseName(r.time_mapping_name);
  if (!kind) fail("unknown time mapping '" + r.time_mapping_name + "'");
  r.time.observer_radius_m = need_d(first, slices[0]->name, "skybake.time_mapping.observer_radius_m");
  r.time.top_radius_m = need_d(first, slices[0]->name, "skybake.time_mapping.top_radius_m");
  r.time.upper_slices = kind->upper;
  r.time.lower_slices = kind->lower;
  r.time.upper_power = kind->upper_power;
  if (!(r.time.observer_radius_m > 0.0 && r.time.top_radius_m > r.time.observer_radius_m)) fail("bad time mapping radii");
  if (static_cast<int>(slices.size()) != r.time.slices()) {
    fail(fmt::format("{} fog LUT slices, but the time mapping '{}' has {}", slices.size(), r.time_mapping_name, r.time.slices()));
  }
  // The texel grid (centres or nodes) is part of the mapping's description: read it from there.
  const std::string* first_mapping = FindStringAttribute(first, "skybake.mapping");
  for (gt7::TexelGrid g : {gt7::TexelGrid::kCentres, gt7::TexelGrid::kNodes}) {
    if (first_mapping && *first_mapping == gt7::Gt7SkyMapping(r.lut_width, r.lut_height, r.sphere, g).Describe()) r.texel_grid = g;
  }
  const std::string expect_mapping = r.mapping().Describe();
  const std::vector<double> expect_zenith = r.time.SliceZenithDeg();
  const size_t texels = static_cast<size_t>(r.lut_width) * r.lut_height;
  for (size_t k = 0; k < slices.size(); ++k) {
    const ExrImage& img = slices[k]->image;
    const std::string& pn = slices[k]->name;
    if (img.width != r.lut_width || img.height != r.lut_height) fail("part '" + pn + "' has another size than the first slice");
    const std::string* mp = FindStringAttribute(img, "skybake.mapping");
    if (!mp || *mp != expect_mapping) fail("part '" + pn + "' is not on the GT7 sphere mapping");
    const double sza = need_d(img, pn, "skybake.sun_zenith_deg");
    if (std::fabs(sza - expect_zenith[k]) > 1e-9) {
      fail(fmt::format("part '{}': sun zenith {} deg, but slice {} of the time mapping is at {} deg", pn, FormatExact(sza), k,
                       FormatExact(expect_zenith[k])));
    }
    same_fog(img, pn);
    r.slice_zenith_deg.push_back(sza);
    int ci[7];
    const char* ch[7] = {"R", "G", "B", "shadowed_R", "shadowed_G", "shadowed_B", "Y_stderr"};
    for (int c = 0; c < 7; ++c) {
      ci[c] = img.ChannelIndex(ch[c]);
      if (ci[c] < 0) fail("part '" + pn + "' lacks the channel " + std::string(ch[c]));
    }
    std::vector<float> xyz(texels * 3), sh(texels * 3), se(texels);
    const size_t nc = img.channels.size();
    for (size_t t = 0; t < texels; ++t) {
      for (int c = 0; c < 3; ++c) {
        xyz[t * 3 + c] = img.pixels[t * nc + ci[c]];
        sh[t * 3 + c] = img.pixels[t * nc + ci[3 + c]];
      }
      se[t] = img.pixels[t * nc + ci[6]];
    }
    finite(xyz, pn);
    finite(sh, pn);
    r.slice_xyz.push_back(std::move(xyz));
    r.slice_shadowed_xyz.push_back(std::move(sh));
    r.slice_y_stderr.push_back(std::move(se));
  }

  // Depth tables.
  for (const ExrPart& p : parts) {
    if (p.name.rfind("depth.", 0) != 0) continue;
    const ExrTable t = ImageToTable(p.image, name);
    if (t.axes.size() != 3 || t.axes[0].name != "depth_x" || t.axes[1].name != "azimuth" || t.axes[2].name != "elevation") {
      fail("part '" + p.name + "' is not a depth_x x azimuth x elevation table");
    }
    same_fog(p.image, p.name);
    if (r.tables.empty()) {
      r.depth_x = t.axes[0].values;
      r.azimuth_deg = t.axes[1].values;
      r.elevation_deg = t.axes[2].values;
    } else if (t.axes[0].values != r.depth_x || t.axes[1].values != r.azimuth_deg || t.axes[2].values != r.elevation_deg) {
      fail("part '" + p.name + "' has other axes than the first depth table");
    }
    for (size_t j = 0; j < r.depth_x.size(); ++j) {
      if (!(r.depth_x[j] > 0.0 && r.depth_x[j] <= 1.0) || (j > 0 && !(r.depth_x[j] > r.depth_x[j - 1]))) {
        fail("part '" + p.name + "': depth_x must increase within (0, 1]");
      }
    }
    for (double e : r.elevation_deg) {
      if (!(e >= 0.0 && e <= 90.0)) fail("part '" + p.name + "': elevations must lie in 0-90 deg");
    }
    FogDepthTable d;
    d.sun_zenith_deg = need_d(p.image, p.name, "skybake.sun_zenith_deg");
    int ci[8];
    const char* ch[8] = {"X", "Y", "Z", "shadowed_X", "shadowed_Y", "shadowed_Z", "Y_stderr", "shadowed_Y_stderr"};
    for (int c = 0; c < 8; ++c) {
      ci[c] = t.ChannelIndex(ch[c]);
      if (ci[c] < 0) fail("part '" + p.name + "' lacks the channel " + std::string(ch[c]));
    }
    for (size_t i = 0; i < t.Count(); ++i) {
      for (int c = 0; c < 3; ++c) {
        d.xyz.push_back(t.At(i, ci[c]));
        d.shadowed_xyz.push_back(t.At(i, ci[3 + c]));
      }
      d.y_stderr.push_back(t.At(i, ci[6]));
      d.shadowed_y_stderr.push_back(t.At(i, ci[7]));
    }
    finite(d.xyz, p.name);
    finite(d.shadowed_xyz, p.name);
    r.tables.push_back(std::move(d));
  }
  if (r.tables.empty()) fail("no depth tables (parts depth.sza_*): render with sky-render fog");

  {
    const ExrTable t = ImageToTable(FindPart(parts, "depth_transmittance", name), name);
    if (t.axes.size() != 3 || t.axes[0].values != r.wavelength_nm || t.axes[1].values != r.depth_x ||
        t.axes[2].values != r.elevation_deg || t.channels.size() != 1) {
      fail("part 'depth_transmittance' is not a wavelength x depth_x x elevation table on the depth tables' axes");
    }
    r.depth_transmittance = t.values;
    finite(r.depth_transmittance, "depth_transmittance");
  }
  {
    const ExrTable t = ImageToTable(FindPart(parts, "attenuation", name), name);
    if (t.axes.size() != 3 || t.axes[0].values != r.wavelength_nm || t.axes[1].name != "u" || t.axes[2].name != "v" ||
        t.channels.size() != 1 || t.axes[1].values.size() < 2 || t.axes[2].values.size() < 2) {
      fail("part 'attenuation' is not a wavelength x u x v table");
    }
    r.attenuation_width = static_cast<int>(t.axes[1].values.size());
    r.attenuation_height = static_cast<int>(t.axes[2].values.size());
    r.attenuation = t.values;
    finite(r.attenuation, "attenuation");
  }
  (void)nw;
  return r;
}

}  // namespace skybake::fog
