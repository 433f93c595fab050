#include "transport/sky_scene.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "atmosphere/mie_optics.h"
#include "atmosphere/model_build.h"
#include "atmosphere/simplify.h"
#include "color/color.h"
#include "color/exr_color.h"
#include "io/csv.h"
#include "io/exr.h"
#include "io/fileio.h"
#include "io/png.h"
#include "io/yaml.h"
#include "lut/directions.h"
#include "lut/gt7_mapping.h"
#include "optics/mie_table.h"
#include "spectrum/spectrum.h"
#include "transport/rgb_color.h"
#include "transport/sky_shard.h"
#include "io/size.h"

namespace fs = std::filesystem;

namespace skybake {

namespace {

std::optional<double> ParseNumber(const std::string& s) {
  double v = 0.0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

AerosolPhase ParseAerosolPhase(const std::string& s) {
  for (AerosolPhase p : {AerosolPhase::kTabulated, AerosolPhase::kHenyeyGreenstein, AerosolPhase::kHenyeyGreensteinMoment,
                         AerosolPhase::kCornetteShanks, AerosolPhase::kDualLobe}) {
    if (s == AerosolPhaseName(p)) return p;
  }
  throw UsageError("--aerosol-phase: expected mie, hg, hg-moment, cornette-shanks or dual-lobe, got '" + s + "'");
}

// The sun's spectrum as a table for the RGB grid's colour rule: its file, or a constant sun as a
// flat table over the observers' whole support (360-830 nm).
TabulatedSpectrum SolarSpectrumOf(const SunSpec& sun) {
  if (!sun.constant_w_m2_nm) return LoadSpectrumColumn(sun.spectrum.file, sun.spectrum.value_column);
  TabulatedSpectrum t;
  t.display_name = "constant sun";
  t.quantity = "constant_W_m2_nm";
  t.wavelength_nm = {300.0, 1000.0};
  t.values = {*sun.constant_w_m2_nm, *sun.constant_w_m2_nm};
  return t;
}

std::string SliceName(double sza) { return fmt::format("sky.sza_{:06.2f}", sza); }

}  // namespace

WavelengthGrid ParseWavelengthGrid(const std::string& text) {
  if (text == "rgb") return WavelengthGrid::Rgb();
  std::vector<double> parts;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ':')) {
    std::optional<double> v = ParseNumber(item);
    if (!v) throw UsageError("--wavelengths: expected min:max:step in nm, got '" + text + "'");
    parts.push_back(*v);
  }
  if (parts.size() != 3) throw UsageError("--wavelengths: expected min:max:step in nm, got '" + text + "'");
  try {
    return WavelengthGrid::Uniform(parts[0], parts[1], parts[2]);
  } catch (const InputError& e) {
    throw UsageError("--wavelengths: " + std::string(e.what()));
  }
}

Scene LoadScene(const SceneOptions& o, const ProgressFn& progress) {
  Scene s;
  s.grid = ParseWavelengthGrid(o.wavelengths);
  std::optional<Observer> obs = ParseObserver(o.observer);
  if (!obs) throw UsageError("--observer: expected cie2006_2deg or cie1931_2deg, got '" + o.observer + "'");
  s.observer = *obs;
  const AerosolPhase phase = ParseAerosolPhase(o.aerosol_phase);
  if (o.illumination != "sun" && o.illumination != "uniform") {
    throw UsageError("--illumination: expected sun or uniform, got '" + o.illumination + "'");
  }

  ReportProgress(progress, "loading", 0.0);
  s.spec = LoadAtmosphere(o.atmosphere);
  s.files_read.push_back(o.atmosphere);
  if (o.profiles.empty()) {
    if (!s.spec.grid) s.spec.grid = GridSpec{100.0};
    s.profiles = ComputeProfiles(s.spec);
    s.files_read.insert(s.files_read.end(), s.profiles.inputs_read.begin(), s.profiles.inputs_read.end());
  } else {
    s.profiles = ProfilesFromTable(ImageToTable(ReadExr(o.profiles), o.profiles), o.profiles);
    s.files_read.push_back(o.profiles);
  }
  if (o.profiles_exponential) s.profiles = AnalyticProfiles(s.profiles);

  // Aerosol optics from the Mie tables: <mie_dir>/<particle file stem>.exr.
  std::vector<AerosolOptics> aerosols;
  for (const AerosolLayerSpec& layer : s.spec.aerosols) {
    if (layer.optics) continue;  // parametric: BuildAtmosphereModel reads its optics from the spec
    if (!layer.particle) {
      throw InputError(FileLoc{s.spec.file.string(), 0}, "aerosol layer '" + layer.name + "' has no 'particle' type");
    }
    if (o.mie_dir.empty()) {
      throw UsageError("aerosol layer '" + layer.name + "' needs its Mie table: pass --mie-dir (the folder of " +
                       layer.particle->stem().string() + ".exr, written by mie-tables)");
    }
    const fs::path table_path = fs::path(o.mie_dir) / (layer.particle->stem().string() + ".exr");
    auto table = std::make_shared<mie::MieTable>(mie::ReadMieTable(table_path));
    s.files_read.push_back(table_path);
    aerosols.push_back(AerosolOpticsFromMie(layer.name, table, s.grid, phase));
  }

  ModelOptions mo;
  mo.ozone = !o.no_ozone;
  s.model = BuildAtmosphereModel(s.spec, s.profiles, s.grid, aerosols, mo, &s.files_read);

  // Colour weights.
  const Cmf cmf = Cmf::LoadDefault(s.observer);
  s.files_read.push_back(cmf.path());
  s.ocio_config = ColorConfig::ResolvePath(o.ocio_config);
  s.files_read.push_back(s.ocio_config);
  if (s.grid.is_spectral()) {
    s.xyz = std::make_shared<XyzWeights>(s.grid, cmf);
    for (size_t i = 0; i < s.grid.size(); ++i) s.xyz_weights.push_back({s.xyz->wx()[i], s.xyz->wy()[i], s.xyz->wz()[i]});
  } else {
    // The RGB grid: Bruneton's sky radiance-to-colour rule (transport/rgb_color.h).
    s.xyz_weights = RgbGridXyzWeights(cmf, SolarSpectrumOf(*s.spec.sun), ColorConfig::Load(s.ocio_config));
  }

  s.tracer.illumination = o.illumination == "uniform" ? Illumination::kUniform : Illumination::kSun;
  s.tracer.target_relative_error = o.target_error;
  s.tracer.min_paths = o.min_paths;
  s.tracer.max_paths = std::max(o.max_paths, o.min_paths);
  s.tracer.seed = o.seed;
  s.tracer.max_order = o.max_order;

  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "wavelengths" << YAML::Value << s.grid.Describe();
  y << YAML::Key << "observer" << YAML::Value << ObserverName(s.observer);
  y << YAML::Key << "aerosol_phase" << YAML::Value << AerosolPhaseName(phase);
  y << YAML::Key << "ozone" << YAML::Value << (o.no_ozone ? "off" : "on");
  y << YAML::Key << "profiles" << YAML::Value << (o.profiles_exponential ? "exponential" : "measured");
  y << YAML::Key << "illumination" << YAML::Value << o.illumination;
  y << YAML::Key << "target_relative_error" << YAML::Value << FormatExact(o.target_error);
  y << YAML::Key << "min_paths" << YAML::Value << o.min_paths;
  y << YAML::Key << "max_paths" << YAML::Value << s.tracer.max_paths;
  y << YAML::Key << "seed" << YAML::Value << o.seed;
  y << YAML::Key << "max_order" << YAML::Value << o.max_order;
  y << YAML::EndMap;
  s.parameters = std::string(y.c_str()) + "\n" + CanonicalRenderYaml(s.spec, fs::path(o.atmosphere).parent_path());
  return s;
}

static gt7::TimeMapping TimeMappingOf(const Scene& scene, const RenderOptions& o, double observer_altitude_m) {
  if (!scene.spec.planet) throw InputError(FileLoc{scene.spec.file.string(), 0}, "--time-mapping needs the 'planet' section");
  return gt7::TimeMapping::FromName(o.time_mapping, scene.spec.planet->radius_m, scene.spec.planet->top_m, observer_altitude_m);
}

RenderProducts RenderProductsOf(const Scene& scene, const RenderOptions& o, const ProgressFn& progress) {
  RenderProducts p;
  const std::optional<Size2> size = ParseSize(o.size, 2, 8192);
  if (!size) throw UsageError("--size: expected " + SizeExpected(2, 8192, "64x32") + ", got '" + o.size + "'");
  const int w = size->width, h = size->height;
  p.settings.mapping = MakeSkyMapping(o.mapping, w, h);
  if (!p.settings.mapping) {
    std::string names;
    for (const std::string& n : SkyMappingNames()) names += (names.empty() ? "" : ", ") + n;
    throw UsageError("--mapping: expected one of " + names + ", got '" + o.mapping + "'");
  }
  for (double z : o.sun_zenith_deg) {
    if (!(z >= 0.0 && z <= 180.0)) throw UsageError(fmt::format("--sun-zenith-deg: {} is outside 0-180", z));
  }
  p.settings.sun_zenith_deg = o.sun_zenith_deg;
  p.settings.observer_altitude_m = o.observer_altitude_m >= 0.0 ? o.observer_altitude_m : scene.spec.observer_altitude_m;
  if (p.settings.observer_altitude_m >= scene.model.altitude_m.back()) {
    throw UsageError("the observer must be inside the atmosphere");
  }
  if (!o.time_mapping.empty()) p.settings.sun_zenith_deg = TimeMappingOf(scene, o, p.settings.observer_altitude_m).SliceZenithDeg();
  if (!o.shard.empty()) {
    const std::optional<ShardSpec> shard = ParseShard(o.shard);
    if (!shard) throw UsageError("--shard: expected K/N with 0 <= K < N <= 4096 (e.g. 0/4), got '" + o.shard + "'");
    // A deterministic render's task is a slice; the path tracer's a texel of a slice, at least
    // half the texels (one of each mirror pair).
    const size_t slices = p.settings.sun_zenith_deg.size();
    const size_t tasks = o.method == "path" ? slices * (static_cast<size_t>(w) * h / 2) : slices;
    if (static_cast<size_t>(shard->count) > tasks) {
      throw UsageError(fmt::format("--shard {}: this render has {} {}, fewer than {} shards", o.shard, tasks,
                                   o.method == "path" ? "texel tasks" : "slices", shard->count));
    }
    if (!o.preview.empty()) throw UsageError("--preview: a shard writes no preview (sky-render merge --preview does)");
    p.settings.shard_index = shard->index;
    p.settings.shard_count = shard->count;
  }
  if (o.method == "path") {
    PathTracer tracer(scene.model, scene.xyz_weights, scene.tracer);
    p.sky = RenderSky(tracer, p.settings, progress);
  } else {
    SkyMethodOptions mo = o.method_options;
    mo.observer_altitude_m = p.settings.observer_altitude_m;
    std::unique_ptr<SkyMethod> method = MakeSkyMethod(o.method, scene.model, mo, progress);
    p.sky = RenderSkyDeterministic(*method, scene.model, scene.xyz_weights, p.settings, progress);
    p.method_description = method->Describe();
  }
  return p;
}

void WriteRender(const Scene& scene, const RenderOptions& o, const RenderProducts& p, const fs::path& path,
                 const std::string& tool) {
  Provenance prov;
  prov.tool = tool;
  prov.parameters = fmt::format("method: {}\nmapping: {}\nsize: {}\n", o.method, o.mapping, o.size) +
                    (o.time_mapping.empty() ? "" : "time_mapping: " + o.time_mapping + "\n") +
                    p.method_description + (o.quality_choice.empty() ? "" : o.quality_choice + "\n") + scene.parameters;
  for (const fs::path& f : scene.files_read) prov.AddInput(f);

  ColorConfig config = ColorConfig::Load(scene.ocio_config);
  ColorProcessor to_reference = config.Converter(XyzColorSpace(scene.observer), ocio_names::kCieXyzD65);
  const SkyMapping& g = *p.settings.mapping;
  const size_t nw = scene.grid.size();
  std::vector<double> slice_zenith_deg;  // the rendered slices' (all of them unless sharded)
  for (const SkySlice& sl : p.sky.slices) slice_zenith_deg.push_back(sl.sun_zenith_deg);
  std::vector<ExrPart> parts;
  for (const SkySlice& sl : p.sky.slices) {
    std::vector<float> rgb = sl.xyz;
    to_reference.Apply(rgb);
    ExrImage img = MakeColorImage(g.width(), g.height(), rgb, ocio_names::kCieXyzD65);
    // Extra channels beside R, G, B.
    ExrImage full;
    full.Resize(g.width(), g.height(), {"R", "G", "B", "Y_stderr", "paths"});
    for (size_t t = 0; t < static_cast<size_t>(g.width()) * g.height(); ++t) {
      for (size_t c = 0; c < 3; ++c) full.pixels[t * 5 + c] = rgb[t * 3 + c];
      full.pixels[t * 5 + 3] = sl.y_stderr[t];
      full.pixels[t * 5 + 4] = sl.paths[t];
    }
    full.chromaticities = img.chromaticities;
    full.strings = img.strings;
    full.strings["skybake.quantity"] = "sky radiance without the sun disk; R, G, B = X, Y, Z (cd/m^2)";
    full.strings["skybake.observer"] = ObserverName(scene.observer);
    full.strings["skybake.mapping"] = g.Describe();
    full.doubles["skybake.sun_zenith_deg"] = sl.sun_zenith_deg;
    full.doubles["skybake.observer_altitude_m"] = p.settings.observer_altitude_m;
    if (!o.time_mapping.empty()) {  // what lut-pack needs to rebuild the slice coordinate
      const gt7::TimeMapping tm = TimeMappingOf(scene, o, p.settings.observer_altitude_m);
      full.strings["skybake.time_mapping"] = o.time_mapping;
      full.strings["skybake.time_mapping.description"] = tm.Describe();
      full.doubles["skybake.time_mapping.observer_radius_m"] = tm.observer_radius_m;
      full.doubles["skybake.time_mapping.top_radius_m"] = tm.top_radius_m;
    }
    SetProvenance(full, prov);
    // Time-mapped renders name parts by slice index too: the GT7 mapping has 90 deg twice.
    const std::string part_name =
        o.time_mapping.empty() ? SliceName(sl.sun_zenith_deg)
                               : fmt::format("sky.slice_{:02d}.sza_{:06.2f}", sl.index, sl.sun_zenith_deg);
    parts.push_back({part_name, std::move(full)});
  }
  // Transmittance table (wavelength x view zenith).
  {
    ExrTable t;
    t.axes.push_back({"wavelength", "nm", scene.grid.Describe(), scene.grid.wavelength_nm()});
    t.axes.push_back({"view_zenith", "deg", "view zenith angle from the observer", p.sky.transmittance_zenith_deg});
    t.channels = {"transmittance"};
    t.channel_units = {"1"};
    for (double v : p.sky.transmittance) t.values.push_back(static_cast<float>(v));
    ExrImage img = TableToImage(t);
    img.strings["skybake.quantity"] = "transmittance from the observer to the top of the atmosphere (0 into the ground)";
    SetProvenance(img, prov);
    parts.push_back({"transmittance", std::move(img)});
  }
  // Direct sun (spectral) and irradiances (colour) per sun angle.
  {
    ExrTable t;
    t.axes.push_back({"wavelength", "nm", scene.grid.Describe(), scene.grid.wavelength_nm()});
    t.axes.push_back({"sun_zenith", "deg", "sun zenith angle", slice_zenith_deg});
    t.channels = {"irradiance"};
    t.channel_units = {"W m^-2 nm^-1"};
    for (const SkySlice& sl : p.sky.slices) {
      for (size_t w = 0; w < nw; ++w) t.values.push_back(static_cast<float>(sl.sun_irradiance[w]));
    }
    ExrImage img = TableToImage(t);
    img.strings["skybake.quantity"] = "direct sun spectral irradiance at the observer, normal incidence (disk-centre transmittance)";
    SetProvenance(img, prov);
    parts.push_back({"sun", std::move(img)});
  }
  {
    ExrTable t;
    t.axes.push_back({"sun_zenith", "deg", "sun zenith angle", slice_zenith_deg});
    t.channels = {"sun_X", "sun_Y", "sun_Z", "sun_horizontal_Y", "ambient_X", "ambient_Y", "ambient_Z", "ambient_Y_stderr"};
    t.channel_units = {"lx", "lx", "lx", "lx", "lx", "lx", "lx", "lx"};
    for (const SkySlice& sl : p.sky.slices) {
      std::vector<float> sun = {static_cast<float>(sl.sun_xyz[0]), static_cast<float>(sl.sun_xyz[1]),
                                static_cast<float>(sl.sun_xyz[2])};
      std::vector<float> amb = {static_cast<float>(sl.ambient.xyz[0]), static_cast<float>(sl.ambient.xyz[1]),
                                static_cast<float>(sl.ambient.xyz[2])};
      to_reference.Apply(sun);
      to_reference.Apply(amb);
      const double mu_s = std::cos(sl.sun_zenith_deg * 3.14159265358979323846 / 180.0);
      std::vector<float> row = {sun[0], sun[1], sun[2], static_cast<float>(sun[1] * std::max(0.0, mu_s)),
                                amb[0], amb[1], amb[2], static_cast<float>(sl.ambient.xyz_stderr[1])};
      t.values.insert(t.values.end(), row.begin(), row.end());
    }
    ExrImage img = TableToImage(t);
    img.strings["skybake.quantity"] =
        "illuminance (X, Y, Z in the CIE-XYZ-D65 reference): direct sun on a surface normal to it and on a horizontal "
        "surface; sky (ambient) on a horizontal surface, without the sun disk";
    SetProvenance(img, prov);
    parts.push_back({"irradiance", std::move(img)});
  }
  if (p.settings.shard_count > 1) {  // transport/sky_shard.h
    std::vector<std::vector<uint8_t>> owned;
    for (const SkySlice& sl : p.sky.slices) owned.push_back(sl.owned);
    parts.push_back({kShardPart, ShardPart({p.settings.shard_index, p.settings.shard_count}, p.settings.sun_zenith_deg.size(),
                                           p.sky.slices.empty() ? 0 : p.sky.slices.front().index, g.width(), g.height(),
                                           owned)});
  }
  WriteExrParts(path, parts);
}

void CheckPreviewOptions(const Scene& scene, const RenderOptions& o) { CheckPreviewOptions(scene.ocio_config, o); }

void CheckPreviewOptions(const fs::path& ocio_config, const RenderOptions& o) {
  ColorConfig config = ColorConfig::Load(ocio_config);
  const std::vector<std::string> displays = config.Displays();
  if (std::find(displays.begin(), displays.end(), o.display) == displays.end()) {
    throw UsageError(fmt::format("--display {}: expected one of the OCIO config's displays: {}", o.display,
                                 fmt::join(displays, ", ")));
  }
  if (o.white != "auto") {
    std::optional<double> w = ParseNumber(o.white);
    if (!w || !(*w > 0.0 && *w <= 1e9)) {
      throw UsageError("--white-cd-m2: expected 'auto' or a luminance in (0, 1e9] cd/m^2, got '" + o.white + "'");
    }
  }
  if (!(std::abs(o.exposure_stops) <= 64.0)) {
    throw UsageError(fmt::format("--exposure: expected stops in [-64, 64], got {}", o.exposure_stops));
  }
}

void WriteRenderPreview(const Scene& scene, const RenderOptions& o, const RenderProducts& p, const fs::path& path) {
  ColorConfig config = ColorConfig::Load(scene.ocio_config);
  ColorProcessor to_reference = config.Converter(XyzColorSpace(scene.observer), ocio_names::kCieXyzD65);
  std::vector<std::vector<float>> rows;
  for (const SkySlice& sl : p.sky.slices) {
    std::vector<float> rgb = sl.xyz;
    for (float& v : rgb) {
      if (!std::isfinite(v)) v = 0.0f;  // outside the mapping: black
    }
    to_reference.Apply(rgb);
    rows.push_back(std::move(rgb));
  }
  WritePreviewOfReference(scene.ocio_config, o, p.settings.mapping->width(), p.settings.mapping->height(), rows, path);
}

void WritePreviewOfReference(const fs::path& ocio_config, const RenderOptions& o, int width, int height,
                             const std::vector<std::vector<float>>& slices, const fs::path& path) {
  ColorConfig config = ColorConfig::Load(ocio_config);
  const size_t texels = static_cast<size_t>(width) * height;
  std::vector<uint8_t> montage;
  for (const std::vector<float>& slice : slices) {
    std::vector<float> rgb = slice;
    for (float& v : rgb) {
      if (!std::isfinite(v)) v = 0.0f;  // outside the mapping: black
    }
    DisplayView view;
    view.display = o.display;
    view.exposure_stops = o.exposure_stops;
    if (o.white == "auto") {
      // The 99th percentile of Y shown as white, row by row (the sky spans 1e-3 to 1e4 cd/m^2).
      std::vector<float> y;
      for (size_t t = 0; t < texels; ++t) y.push_back(rgb[t * 3 + 1]);
      std::sort(y.begin(), y.end());
      view.white_cd_m2 = std::max(1e-9, static_cast<double>(y[std::min(y.size() - 1, y.size() * 99 / 100)]));
    } else {
      std::optional<double> w = ParseNumber(o.white);
      if (!w || *w <= 0.0) throw UsageError("--white-cd-m2: expected a positive number or 'auto', got '" + o.white + "'");
      view.white_cd_m2 = *w;
    }
    ColorProcessor display = config.Display(ocio_names::kCieXyzD65, view);
    std::vector<uint8_t> row = EncodePreview8(width, height, rgb, display);
    montage.insert(montage.end(), row.begin(), row.end());
  }
  WritePng8(path, width, height * static_cast<int>(slices.size()), 3, montage);
}

}  // namespace skybake
