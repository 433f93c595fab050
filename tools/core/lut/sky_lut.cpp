#include "lut/sky_lut.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "io/error.h"
#include "io/exr.h"
#include "io/exr_attributes.h"
#include "io/yaml.h"
#include "lut/r11g11b10.h"
#include "spectrum/cmf.h"
#include "spectrum/grid.h"
#include "spectrum/xyz.h"

namespace fs = std::filesystem;

namespace skybake::lut {

namespace {

constexpr double kPi = std::numbers::pi;

std::string Join(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : " ") + FormatExact(x);
  return s;
}

// The value of the first provenance line "<key>: value" of the render's parameters ("" if none).
std::string ParameterOf(const ExrImage& img, const std::string& key) {
  const std::string* p = FindStringAttribute(img, "skybake.parameters");
  if (!p) return "";
  const std::string tag = key + ": ";
  size_t at = 0;
  if (p->compare(0, tag.size(), tag) != 0) {
    at = p->find("\n" + tag);
    if (at == std::string::npos) return "";
    ++at;
  }
  const size_t end = p->find('\n', at);
  return p->substr(at + tag.size(), end == std::string::npos ? std::string::npos : end - at - tag.size());
}

}  // namespace

// ------------------------------------------------------------------------------------- reading

SkyRender ReadSkyRender(const fs::path& path) {
  const std::string name = path.string();
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, msg); };
  const std::vector<ExrPart> parts = ReadExrParts(path);
  SkyRender r;
  r.path = name;
  std::vector<const ExrPart*> slices;
  for (const ExrPart& p : parts) {
    if (p.name.rfind("sky.", 0) != 0) continue;
    const int index = NumberedPartIndex(p.name, "sky.slice_");
    if (index < 0) {
      fail("part '" + p.name + "' is not a slice of the GT7 time mapping: render with sky-render render --mapping gt7 "
           "--time-mapping gt7");
    }
    if (index != static_cast<int>(slices.size())) fail(fmt::format("part '{}' is out of order (expected slice {})", p.name, slices.size()));
    slices.push_back(&p);
  }
  if (slices.size() < 4) fail(fmt::format("{} sky slices; a GT7 LUT needs at least 4 (2 upper + 2 lower)", slices.size()));

  const ExrImage& first = slices[0]->image;
  r.width = first.width;
  r.height = first.height;
  const std::string* tm_name = FindStringAttribute(first, "skybake.time_mapping");
  const double* obs_r = FindDoubleAttribute(first, "skybake.time_mapping.observer_radius_m");
  const double* top_r = FindDoubleAttribute(first, "skybake.time_mapping.top_radius_m");
  if (!tm_name || !obs_r || !top_r) fail("part '" + slices[0]->name + "' has no skybake.time_mapping attributes: render with --time-mapping gt7");
  const std::optional<gt7::TimeMappingKind> n = gt7::TimeMapping::ParseName(*tm_name);
  if (!n) fail("unknown time mapping '" + *tm_name + "'");
  r.time_mapping_name = *tm_name;
  r.time.observer_radius_m = *obs_r;
  r.time.top_radius_m = *top_r;
  r.time.upper_slices = n->upper;
  r.time.lower_slices = n->lower;
  r.time.upper_power = n->upper_power;
  if (!(r.time.observer_radius_m > 0.0 && r.time.top_radius_m > r.time.observer_radius_m)) fail("bad time mapping radii");
  if (static_cast<int>(slices.size()) != r.time.slices()) {
    fail(fmt::format("{} sky slices, but the time mapping '{}' has {}", slices.size(), *tm_name, r.time.slices()));
  }
  const std::string expect_mapping = gt7::Gt7SkyMapping(r.width, r.height, r.sphere).Describe();
  const std::vector<double> expect_zenith = r.time.SliceZenithDeg();
  for (size_t k = 0; k < slices.size(); ++k) {
    const ExrImage& img = slices[k]->image;
    const std::string& pn = slices[k]->name;
    if (img.width != r.width || img.height != r.height) {
      fail(fmt::format("part '{}' is {}x{}, the first slice {}x{}", pn, img.width, img.height, r.width, r.height));
    }
    const std::string* mapping = FindStringAttribute(img, "skybake.mapping");
    if (!mapping || *mapping != expect_mapping) {
      fail("part '" + pn + "' was not rendered on lut-pack's GT7 sphere mapping (render with --mapping gt7): " +
           (mapping ? "'" + mapping->substr(0, 60) + "...'" : std::string("no skybake.mapping")));
    }
    const std::string* tn = FindStringAttribute(img, "skybake.time_mapping");
    const double* o2 = FindDoubleAttribute(img, "skybake.time_mapping.observer_radius_m");
    const double* t2 = FindDoubleAttribute(img, "skybake.time_mapping.top_radius_m");
    if (!tn || *tn != *tm_name || !o2 || *o2 != *obs_r || !t2 || *t2 != *top_r) {
      fail("part '" + pn + "' has another time mapping than the first slice");
    }
    const double* sza = FindDoubleAttribute(img, "skybake.sun_zenith_deg");
    if (!sza || std::fabs(*sza - expect_zenith[k]) > 1e-9) {
      fail(fmt::format("part '{}': sun zenith {} deg, but slice {} of the time mapping is at {} deg", pn,
                       sza ? FormatExact(*sza) : std::string("(none)"), k, FormatExact(expect_zenith[k])));
    }
    r.slice_zenith_deg.push_back(*sza);
    const int ci[3] = {img.ChannelIndex("R"), img.ChannelIndex("G"), img.ChannelIndex("B")};
    if (ci[0] < 0 || ci[1] < 0 || ci[2] < 0) fail("part '" + pn + "' lacks the R, G, B (= X, Y, Z) channels");
    const size_t nc = img.channels.size(), texels = static_cast<size_t>(r.width) * r.height;
    std::vector<float> xyz(texels * 3);
    for (size_t t = 0; t < texels; ++t) {
      for (int c = 0; c < 3; ++c) {
        const float v = img.pixels[t * nc + ci[c]];
        if (!std::isfinite(v)) {
          fail(fmt::format("part '{}': texel ({}, {}) is not finite (every GT7 texel is a direction)", pn, t % r.width,
                           t / r.width));
        }
        xyz[t * 3 + c] = v;
      }
    }
    r.slice_xyz.push_back(std::move(xyz));
    const std::string* obs = FindStringAttribute(img, "skybake.observer");
    if (!obs) fail("part '" + pn + "' has no skybake.observer");
    if (k == 0) r.observer = *obs;
    else if (*obs != r.observer) fail("part '" + pn + "' has another observer than the first slice");
  }
  r.method = ParameterOf(first, "method");
  r.quality_choice = ParameterOf(first, "quality_choice");

  // Transmittance (wavelength x view zenith), direct sun (wavelength x sun zenith), irradiances.
  const ExrTable tr = ImageToTable(FindPart(parts, "transmittance", name), name);
  if (tr.axes.size() != 2 || tr.axes[0].name != "wavelength" || tr.axes[1].name != "view_zenith" || tr.channels.size() != 1) {
    fail("part 'transmittance' is not a wavelength x view_zenith table");
  }
  r.wavelength_nm = tr.axes[0].values;
  r.transmittance_zenith_deg = tr.axes[1].values;
  r.transmittance = tr.values;
  const ExrTable sun = ImageToTable(FindPart(parts, "sun", name), name);
  if (sun.axes.size() != 2 || sun.axes[0].values != r.wavelength_nm || sun.axes[1].values.size() != slices.size()) {
    fail("part 'sun' is not a wavelength x sun_zenith table on the slices");
  }
  r.sun_irradiance = sun.values;
  const ExrTable irr = ImageToTable(FindPart(parts, "irradiance", name), name);
  const char* cols[6] = {"sun_X", "sun_Y", "sun_Z", "ambient_X", "ambient_Y", "ambient_Z"};
  int ic[6];
  for (int c = 0; c < 6; ++c) {
    ic[c] = irr.ChannelIndex(cols[c]);
    if (ic[c] < 0) fail(std::string("part 'irradiance' lacks ") + cols[c]);
  }
  if (irr.Count() != slices.size()) fail("part 'irradiance' does not have one row per slice");
  for (size_t k = 0; k < slices.size(); ++k) {
    r.sun_xyz.push_back({irr.At(k, ic[0]), irr.At(k, ic[1]), irr.At(k, ic[2])});
    r.ambient_xyz.push_back({irr.At(k, ic[3]), irr.At(k, ic[4]), irr.At(k, ic[5])});
  }
  return r;
}

// ------------------------------------------------------------------------------------- packing

PackedTexture PackRgb(int width, int height, int depth, const std::vector<float>& rgb, double scale,
                      const ColorProcessor& to_xyz) {
  const size_t n = static_cast<size_t>(width) * height * depth;
  SKYBAKE_CHECK_EQ(rgb.size(), n * 3);
  SKYBAKE_CHECK(scale > 0.0);
  PackedTexture t;
  t.width = width;
  t.height = height;
  t.depth = depth;
  t.scale = scale;
  t.input_rgb = rgb;
  std::vector<float> stored(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) stored[i] = static_cast<float>(rgb[i] * scale);
  t.bytes = r11g11b10::PackTexels(stored);
  const std::vector<float> back = r11g11b10::UnpackTexels(t.bytes);
  t.decoded_rgb.resize(back.size());
  for (size_t i = 0; i < back.size(); ++i) t.decoded_rgb[i] = static_cast<float>(back[i] / scale);

  // Luminance of the input and of the decoded texels through OCIO (Rec.2020 -> CIE-XYZ-D65).
  std::vector<float> xyz_in = rgb, xyz_out = t.decoded_rgb;
  to_xyz.Apply(xyz_in);
  to_xyz.Apply(xyz_out);

  PackStats& s = t.stats;
  s.texels = n;
  t.clamp_flags.assign(n, 0);
  std::vector<double> errs;
  errs.reserve(n);
  double sum2 = 0.0;
  const float max_c[3] = {r11g11b10::kMaxFinite11, r11g11b10::kMaxFinite11, r11g11b10::kMaxFinite10};
  for (size_t i = 0; i < n; ++i) {
    uint8_t f = 0;
    double y = xyz_in[3 * i + 1];
    double most_negative = 0.0;
    for (int c = 0; c < 3; ++c) {
      const float v = stored[3 * i + c];
      s.max_value = std::max(s.max_value, static_cast<double>(v));
      if (v > max_c[c]) f |= 1;
      if (v < 0.0f) {
        f |= 2;
        most_negative = std::min(most_negative, static_cast<double>(rgb[3 * i + c]));
      }
      if (v > 0.0f && v < r11g11b10::kMinNormal) f |= 4;
    }
    t.clamp_flags[i] = f;
    if (f & 1) ++s.clamped_high;
    if (f & 2) {
      ++s.negative_texels;
      if (y > 0.0) s.worst_negative_fraction = std::max(s.worst_negative_fraction, -most_negative / y);
    }
    if (f & 4) ++s.denormal_texels;
    if (!(y > 0.0)) {
      ++s.zero_luminance;
      continue;
    }
    if (f) continue;
    const double e = std::fabs(xyz_out[3 * i + 1] - y) / y;
    errs.push_back(e);
    sum2 += e * e;
    if (e > s.y_rel_max) {
      s.y_rel_max = e;
      s.worst_texel = i;
    }
    for (int c = 0; c < 3; ++c) {
      const double in = rgb[3 * i + c];
      if (in > 0.0) s.channel_rel_max[c] = std::max(s.channel_rel_max[c], std::fabs(t.decoded_rgb[3 * i + c] - in) / in);
    }
    const double pct = 100.0 * e;
    const int bin = pct < 0.1 ? 0 : pct < 0.2 ? 1 : pct < 0.4 ? 2 : pct < 0.6 ? 3 : pct < 1.0 ? 4 : 5;
    ++s.y_rel_histogram[bin];
  }
  s.measured = errs.size();
  if (!errs.empty()) {
    s.y_rel_rms = std::sqrt(sum2 / static_cast<double>(errs.size()));
    std::sort(errs.begin(), errs.end());
    const double ps[5] = {0.5, 0.9, 0.99, 0.999, 1.0};
    for (int k = 0; k < 5; ++k) {
      const size_t rank = static_cast<size_t>(std::ceil(ps[k] * static_cast<double>(errs.size())));
      s.y_rel_percentiles[k] = errs[std::clamp<size_t>(rank, 1, errs.size()) - 1];
    }
  }
  return t;
}

double AutomaticScale(const std::vector<float>& rgb) {
  double m = 0.0;
  for (float v : rgb) m = std::max(m, static_cast<double>(v));
  double scale = 1.0;
  while (m * scale > r11g11b10::kMaxFinite10) scale *= 0.5;
  return scale;
}

// ------------------------------------------------------------------------------------- the set

LutSet BuildLutSet(const std::vector<std::pair<std::string, const SkyRender*>>& renders, const LutSetOptions& options,
                   const ColorConfig& config, std::vector<fs::path>* files_read) {
  SKYBAKE_CHECK(!renders.empty());
  LutSet set;
  set.options = options;
  const SkyRender& ref = *renders[0].second;
  for (const auto& [name, r] : renders) {
    if (r->time.observer_radius_m != ref.time.observer_radius_m || r->time.top_radius_m != ref.time.top_radius_m ||
        !(r->time.kind() == ref.time.kind())) {
      throw InputError(FileLoc{r->path, 0},
                       "its GT7 time mapping differs from " + ref.path +
                           "'s (planet radius, top of the atmosphere or observer altitude): the basis skies of one "
                           "set share one time coordinate");
    }
    if (r->transmittance_zenith_deg != ref.transmittance_zenith_deg) {
      throw InputError(FileLoc{r->path, 0}, "its transmittance angles differ from " + ref.path + "'s");
    }
  }
  const ColorProcessor to2020 = config.Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  const int slices = ref.time.slices();
  std::vector<float> sun_rgb, amb_rgb, tr_rgb;
  for (const auto& [name, r] : renders) {
    SkyLutProduct p;
    p.name = name;
    p.render = r;
    std::vector<float> rgb;
    rgb.reserve(static_cast<size_t>(r->width) * r->height * slices * 3);
    for (const std::vector<float>& s : r->slice_xyz) rgb.insert(rgb.end(), s.begin(), s.end());
    to2020.Apply(rgb);
    p.sky = PackRgb(r->width, r->height, slices, rgb, options.sky_scale > 0.0 ? options.sky_scale : AutomaticScale(rgb), to_xyz);

    std::vector<float> sun, amb;
    for (int k = 0; k < slices; ++k) {
      sun.insert(sun.end(), r->sun_xyz[k].begin(), r->sun_xyz[k].end());
      amb.insert(amb.end(), r->ambient_xyz[k].begin(), r->ambient_xyz[k].end());
    }
    to2020.Apply(sun);
    to2020.Apply(amb);
    // The night constant: the uniform radiance whose horizontal illuminance is the last slice's
    // ambient illuminance, E = pi L (Lambert), per channel.
    for (int c = 0; c < 3; ++c) p.night_rgb[c] = std::max(0.0, static_cast<double>(amb[3 * (slices - 1) + c])) / kPi;
    sun_rgb.insert(sun_rgb.end(), sun.begin(), sun.end());
    amb_rgb.insert(amb_rgb.end(), amb.begin(), amb.end());

    // Transmittance colours: T_c(theta) = [E0 T(theta)]_c / [E0]_c, the Rec.2020 channels of
    // sunlight after and before the path (E0 = E(lambda, sun zenith 0) / T(lambda, 0): slice 0 of
    // the GT7 time mapping is the zenith sun; sky_render.cpp computes both with one quadrature).
    const std::optional<Observer> obs = ParseObserver(r->observer);
    if (!obs) throw InputError(FileLoc{r->path, 0}, "unknown observer '" + r->observer + "'");
    const Cmf cmf = Cmf::LoadDefault(*obs);
    if (files_read) files_read->push_back(cmf.path());
    const size_t nw = r->wavelength_nm.size();
    const XyzWeights w(WavelengthGrid::List(r->wavelength_nm, FileLoc{r->path, 0}), cmf);
    if (r->slice_zenith_deg[0] != 0.0 || r->transmittance_zenith_deg.empty() || r->transmittance_zenith_deg[0] != 0.0) {
      throw InputError(FileLoc{r->path, 0}, "the first slice and the first transmittance angle must be the zenith");
    }
    std::vector<double> e0(nw);
    for (size_t l = 0; l < nw; ++l) {
      const double t0 = r->transmittance[l];
      if (!(t0 > 0.0)) {
        throw InputError(FileLoc{r->path, 0}, fmt::format("zero zenith transmittance at {} nm: the extraterrestrial "
                                                          "spectrum cannot be recovered", FormatExact(r->wavelength_nm[l])));
      }
      e0[l] = r->sun_irradiance[l] / t0;
    }
    const ColorProcessor obs_to2020 = config.Converter(XyzColorSpace(*obs), ocio_names::kLinearRec2020);
    const Xyz x0 = w.Integrate(std::span<const double>(e0));
    const std::array<float, 3> ref_rgb =
        obs_to2020.Apply(std::array<float, 3>{static_cast<float>(x0.X), static_cast<float>(x0.Y), static_cast<float>(x0.Z)});
    for (size_t a = 0; a < r->transmittance_zenith_deg.size(); ++a) {
      std::vector<double> spec(nw);
      for (size_t l = 0; l < nw; ++l) spec[l] = e0[l] * r->transmittance[a * nw + l];
      const Xyz x = w.Integrate(std::span<const double>(spec));
      const std::array<float, 3> c =
          obs_to2020.Apply(std::array<float, 3>{static_cast<float>(x.X), static_cast<float>(x.Y), static_cast<float>(x.Z)});
      for (int k = 0; k < 3; ++k) tr_rgb.push_back(static_cast<float>(c[k] / ref_rgb[k]));
    }
    set.skies.push_back(std::move(p));
  }
  const int rows = static_cast<int>(renders.size());
  set.transmittance_zenith_deg = ref.transmittance_zenith_deg;
  set.sun = PackRgb(slices, rows, 1, sun_rgb, AutomaticScale(sun_rgb), to_xyz);
  set.ambient = PackRgb(slices, rows, 1, amb_rgb, AutomaticScale(amb_rgb), to_xyz);
  set.transmittance = PackRgb(static_cast<int>(ref.transmittance_zenith_deg.size()), rows, 1, tr_rgb,
                              AutomaticScale(tr_rgb), to_xyz);
  return set;
}

// ------------------------------------------------------------------------------------- KTX2

namespace {

void SetMappingKeys(ktx2::Texture& tex, const SkyRender& r) {
  ktx2::SetString(tex, "skybake.time_mapping", r.time.Describe());
  ktx2::SetString(tex, "skybake.time_mapping.name", r.time_mapping_name);
  ktx2::SetString(tex, "skybake.time_mapping.observer_radius_m", FormatExact(r.time.observer_radius_m));
  ktx2::SetString(tex, "skybake.time_mapping.top_radius_m", FormatExact(r.time.top_radius_m));
  ktx2::SetString(tex, "skybake.slice_zenith_deg", Join(r.slice_zenith_deg));
}

}  // namespace

ktx2::Texture SkyKtx2(const LutSet& set, const SkyLutProduct& sky, bool array, const Provenance& provenance) {
  const SkyRender& r = *sky.render;
  ktx2::Texture tex;
  tex.format = ktx2::B10G11R11UfloatPack32();
  tex.width = static_cast<uint32_t>(r.width);
  tex.height = static_cast<uint32_t>(r.height);
  if (array) {
    tex.layers = static_cast<uint32_t>(r.time.slices());
  } else {
    tex.depth = static_cast<uint32_t>(r.time.slices());
  }
  ktx2::SetProvenance(tex, provenance);
  ktx2::SetString(tex, "KTXorientation", array ? "rd" : "rdi");
  ktx2::SetString(tex, "skybake.basis_sky", sky.name);
  ktx2::SetString(tex, "skybake.quantity",
                  "sky radiance without the sun disk (cd/m^2 of luminance) in Linear Rec.2020 (OCIO), times skybake.scale; "
                  "texel (x, y, slice) is the direction of the GT7 sphere mapping at u = (x + 1/2)/W, v = (y + 1/2)/H for "
                  "the sun zenith angle of the slice");
  ktx2::SetString(tex, "skybake.colorspace", ocio_names::kLinearRec2020);
  ktx2::SetString(tex, "skybake.unit", "cd/m^2");
  ktx2::SetString(tex, "skybake.scale", FormatExact(sky.sky.scale));
  ktx2::SetString(tex, "skybake.sphere_mapping", r.sphere.Describe());
  ktx2::SetString(tex, "skybake.sphere_mapping.threshold_elevation_deg", FormatExact(r.sphere.threshold_elevation_deg));
  SetMappingKeys(tex, r);
  ktx2::SetString(tex, "skybake.night",
                  fmt::format("below the last slice (sun zenith {} deg) the decoded sky moves linearly from the last slice "
                              "to the uniform radiance skybake.night_rgb (= ambient illuminance of the last slice / pi), "
                              "reached at sun zenith {} deg, and stays there",
                              FormatExact(r.slice_zenith_deg.back()), FormatExact(set.options.night_end_zenith_deg)));
  ktx2::SetString(tex, "skybake.night_rgb",
                  fmt::format("{} {} {}", FormatExact(sky.night_rgb[0]), FormatExact(sky.night_rgb[1]), FormatExact(sky.night_rgb[2])));
  ktx2::SetString(tex, "skybake.night_end_zenith_deg", FormatExact(set.options.night_end_zenith_deg));
  ktx2::SetString(tex, "skybake.sampling",
                  "bilinear filtering, clamp-to-edge in u and v; slice coordinate s of the sun zenith theta from the time "
                  "mapping; read slices i = min(floor(s), N - 2) and i + 1, each with its own sphere-mapping family at the "
                  "target sun zenith (sun-aligned slices at min(theta, threshold zenith)), and blend them geometrically per "
                  "channel, max(a, 1e-6)^(1 - t) max(b, 1e-6)^t with t = (theta - theta_i)/(theta_i+1 - theta_i) (values "
                  "in cd/m^2; docs/lut-pack.md, 'Decoding')");
  ktx2::SetString(tex, "skybake.time_interpolation", "geometric");
  tex.data = sky.sky.bytes;
  return tex;
}

ktx2::Texture TableKtx2(const LutSet& set, const PackedTexture& t, const std::string& quantity, const std::string& axis_u,
                        const Provenance& provenance) {
  ktx2::Texture tex;
  tex.format = ktx2::B10G11R11UfloatPack32();
  tex.width = static_cast<uint32_t>(t.width);
  tex.height = static_cast<uint32_t>(t.height);
  ktx2::SetProvenance(tex, provenance);
  ktx2::SetString(tex, "KTXorientation", "rd");
  std::string rows;
  for (const SkyLutProduct& s : set.skies) rows += (rows.empty() ? "" : " ") + s.name;
  ktx2::SetString(tex, "skybake.rows", rows);
  ktx2::SetString(tex, "skybake.quantity", quantity);
  ktx2::SetString(tex, "skybake.colorspace", ocio_names::kLinearRec2020);
  ktx2::SetString(tex, "skybake.scale", FormatExact(t.scale));
  ktx2::SetString(tex, "skybake.axis_u", axis_u);
  SetMappingKeys(tex, *set.skies[0].render);
  tex.data = t.bytes;
  return tex;
}

}  // namespace skybake::lut
