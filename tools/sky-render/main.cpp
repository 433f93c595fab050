// sky-render: sky radiance, transmittance, direct sun and ambient irradiance of an atmosphere
// (docs/sky-render.md).
//
//   sky-render render ATMOSPHERE.yaml -o sky.exr [--profiles profiles.exr] [--mie-dir outputs/mie]
//              [--method path] [--mapping equirectangular|fisheye] [--size 64x32]
//              [--sun-zenith-deg 30,70,85,90,94 | --time-mapping gt7] [--target-error 0.01] [--preview sky.png] ...
//   sky-render points ATMOSPHERE.yaml --geometry in.csv -o out.csv [--wavelengths-out 440,550,680]
//   sky-render budget ATMOSPHERE.yaml -o budget.csv [--tolerance 1%] [--method ms-approx] ...
//   sky-render choose ATMOSPHERE.yaml -o quality.yaml [--tolerance 0.5%] [--max-tolerance 2%] ...
//              then   sky-render render ATMOSPHERE.yaml --settings quality.yaml ...   (quality: auto)
//   sky-render fog ATMOSPHERE.yaml -o fog.exr [--method orders|path] [--cut-altitude-km 1] ... (docs/fog.md)
//   sky-render render ... --shard K/N -o part_K.exr   then   sky-render merge part_*.exr -o sky.exr [--preview sky.png]
//   sky-render fog ... --shard K/N -o part_K.exr      then   sky-render merge part_*.exr -o fog.exr
//              (shards of one render and their merge, the unsharded bytes; docs/cluster.md)
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "atmosphere/mie_optics.h"
#include "atmosphere/model_build.h"
#include "atmosphere/spec.h"
#include "atmosphere/vertical_profiles.h"
#include "color/color.h"
#include "color/exr_color.h"
#include "fog/fog_render.h"
#include "fog/fog_shard.h"
#include "io/cli.h"
#include "io/csv.h"
#include "io/error.h"
#include "io/exr.h"
#include "io/fileio.h"
#include "io/repo_paths.h"
#include "io/text_list.h"
#include "lut/directions.h"
#include "spectrum/cmf.h"
#include "spectrum/xyz.h"
#include "transport/auto_quality.h"
#include "transport/budget.h"
#include "transport/path_tracer.h"
#include "transport/points.h"
#include "transport/quality.h"
#include "transport/sky_method.h"
#include "transport/sky_render.h"
#include "transport/sky_scene.h"
#include "transport/sky_shard.h"
#include "io/size.h"

namespace fs = std::filesystem;
using namespace skybake;

int main(int argc, char** argv) {
  ToolCli cli("sky-render",
              "Renders the sky of an atmosphere: spectral Monte-Carlo path tracing (the reference), output as\n"
              "absolute XYZ radiance on a direction grid for a list of sun zenith angles, with transmittance,\n"
              "direct sun and ambient irradiance. See docs/sky-render.md.");
  cli.app().require_subcommand(1);
  cli.app().fallthrough();
  SceneOptions scene;
  std::string output, depfile;

  auto add_scene_options = [&](CLI::App* sub) {
    sub->add_option("atmosphere", scene.atmosphere, "Atmosphere YAML (full, or its render component)")->required();
    sub->add_option("--profiles", scene.profiles, "profiles.exr from profile-import (default: computed from the atmosphere)");
    sub->add_option("--mie-dir", scene.mie_dir, "Folder with the Mie tables <particle>.exr of the aerosol layers");
    sub->add_option("--wavelengths", scene.wavelengths,
                    "Spectral grid min:max:step in nm, or rgb (680/550/440 nm, Bruneton's colour rule; docs/sky-methods.md)")
        ->default_val("360:830:5");
    sub->add_option("--observer", scene.observer, "Colour-matching functions: cie2006_2deg or cie1931_2deg")
        ->default_val("cie2006_2deg");
    sub->add_option("--aerosol-phase", scene.aerosol_phase, "Phase model of the particle-type aerosol layers: mie, hg, hg-moment, cornette-shanks, dual-lobe (parametric layers keep their own)")
        ->default_val("mie");
    sub->add_flag("--no-ozone", scene.no_ozone, "Drop ozone and the absorbing layers (a simplification to measure)");
    sub->add_flag("--profiles-exponential", scene.profiles_exponential,
                  "Exponential air and aerosol profiles and a tent of ozone with the measured columns (a simplification)");
    sub->add_option("--illumination", scene.illumination, "sun, or uniform (unit radiance from space: the white furnace)")
        ->default_val("sun");
    sub->add_option("--target-error", scene.target_error, "Target relative standard error of Y per estimate")
        ->default_val(0.01)->check(CLI::Range(1e-4, 1.0));
    sub->add_option("--min-paths", scene.min_paths, "Paths per estimate at least")->default_val(64);
    sub->add_option("--max-paths", scene.max_paths, "Paths per estimate at most")->default_val(1u << 20);
    sub->add_option("--seed", scene.seed, "Random seed")->default_val(1);
    sub->add_option("--max-order", scene.max_order, "Highest scattering order (0 = all)")->default_val(0);
    sub->add_option("--ocio-config", scene.ocio_config, "OCIO config (default: $SKYBAKE_OCIO or the repo's ocio/config.ocio)");
    sub->add_option("-o,--output", output, "Output file")->required();
    sub->add_option("--depfile", depfile, "Write a Make-style depfile of every file read");
  };

  // --quality: a preset name of transport/quality.h, bound to the enum.
  auto add_quality = [](CLI::App* sub, Quality* quality, const std::string& help) {
    sub->add_option("--quality", *quality, help + ": " + QualityNamesText())
        ->transform(CLI::Validator(
            [](std::string& text) {
              const std::optional<Quality> q = FindQuality(text);
              if (!q) return "expected " + QualityNamesText() + ", got '" + text + "'";
              text = std::to_string(static_cast<int>(*q));
              return std::string();
            },
            "", "quality"))
        ->type_name("TEXT")
        ->default_str(QualityName(*quality));
  };
  const std::vector<std::string> methods = SkyMethodNames();

  CLI::App* render = cli.app().add_subcommand("render", "Sky images (EXR, multi-part) for a list of sun zenith angles");
  add_scene_options(render);
  RenderOptions ro;
  render->add_option("--method", ro.method, "Rendering method: path (the Monte-Carlo reference), " + TextList(methods, ", "))
      ->default_val("path");
  add_quality(render, &ro.method_options.quality, "Deterministic methods");
  render->add_option("--spectral-stride", ro.method_options.spectral_stride,
                     "Deterministic methods: run on every k-th wavelength (and the last), the transfer "
                     "interpolated to the grid (docs/sky-methods.md)")
      ->default_val(1);
  std::string settings_file;
  CLI::Option* settings_opt = render->add_option(
      "--settings", settings_file,
      "Method, quality and spectral stride from a file of sky-render choose (quality: auto; docs/sky-methods.md "
      "\"Automatic quality\"), recorded in the provenance");
  render->add_option("--mapping", ro.mapping, "Direction mapping: equirectangular, fisheye or gt7 (lut-pack's, docs/lut-pack.md)")->default_val("equirectangular");
  render->add_option("--size", ro.size, "Image size WxH")->default_val("64x32");
  CLI::Option* sza = render->add_option("--sun-zenith-deg", ro.sun_zenith_deg, "Sun zenith angles (deg), comma separated")
      ->delimiter(',')->default_str("30,70,85,90,94");
  render->add_option("--time-mapping", ro.time_mapping,
                     "Render the sun angles of the GT7 time mapping instead: gt7 (48 + 16 slices) or gt7:<upper>+<lower> "
                     "(docs/lut-pack.md)")
      ->excludes(sza);
  render->add_option("--observer-altitude-m", ro.observer_altitude_m, "Override the atmosphere's observer altitude (m)");
  render->add_option("--shard", ro.shard,
                     "Render only shard K of N (K/N, 0 <= K < N): a contiguous range of the slices (path: of the "
                     "slices' texels), joined by sky-render merge into the unsharded bytes (docs/cluster.md)");
  render->add_option("--preview", ro.preview, "Also write a PNG preview (one row per sun angle, through the OCIO view)");
  render->add_option("--display", ro.display, "Preview display: sRGB, Rec.1886 Rec.709 or Rec.2100-PQ")->default_val("sRGB");
  render->add_option("--white-cd-m2", ro.white, "Preview: luminance shown as white, or 'auto' per row")->default_val("auto");
  render->add_option("--exposure", ro.exposure_stops, "Preview exposure in stops")->default_val(0.0);

  CLI::App* points = cli.app().add_subcommand("points", "Spectral radiance for explicit geometries (CSV in, CSV out)");
  add_scene_options(points);
  PointsOptions po;
  points->add_option("--geometry", po.geometry,
                     "CSV (first line '# source: ...'): sun_zenith_deg, view_zenith_deg, relative_azimuth_deg "
                     "[, observer_altitude_m or _km]")
      ->required();
  points->add_option("--wavelengths-out", po.wavelengths_nm, "Output wavelengths (nm, on the grid)")->delimiter(',')->default_str("440,550,680");
  points->add_option("--method", po.method, "path (the Monte-Carlo reference), " + TextList(methods))->default_val("path");
  add_quality(points, &po.method_options.quality, "Deterministic methods");
  points->add_option("--spectral-stride", po.method_options.spectral_stride,
                     "Deterministic methods: run on every k-th wavelength (and the last), the transfer interpolated")
      ->default_val(1);
  points->add_option("--paths", po.paths,
                     "path: a fixed number of paths per row (default: adaptive, --target-error between --min-paths and "
                     "--max-paths)");

  CLI::App* budget = cli.app().add_subcommand(
      "budget", "Which model simplifications stay under a tolerance, what each costs, which LUT dimensions can be dropped");
  add_scene_options(budget);
  BudgetOptions bo;
  std::string tolerance = "1%", altitude_range;
  budget->add_option("--tolerance", tolerance, "Largest acceptable relative luminance error, e.g. 1% or 0.01")->default_val("1%");
  budget->add_option("--criterion", bo.criterion, "rms or max of the error over the sky (outside a 1 deg aureole)")->default_val("rms");
  budget->add_option("--method", bo.method, "Deterministic evaluator of every item")->default_val("ms-approx");
  add_quality(budget, &bo.quality, "The evaluator's quality");
  budget->add_option("--sun-zenith-deg", bo.sun_zenith_deg, "Sun zenith angles (deg), comma separated")
      ->delimiter(',')->default_str("30,70,85,90,94");
  budget->add_option("--altitude-range-m", altitude_range,
                     "Observer altitude range lo:hi (m) for the altitude dimension (default: the observer's + 0..300 m)");

  CLI::App* choose = cli.app().add_subcommand(
      "choose", "The cheapest quality and spectral stride of a deterministic method within tolerances of its full model "
                "(quality: auto; docs/sky-methods.md \"Automatic quality\")");
  add_scene_options(choose);
  AutoQualityOptions ao;
  std::string choose_rms = "0.5%", choose_max = "2%", choose_twilight = "3%";
  choose->add_option("--tolerance", choose_rms, "Daylight RMS relative luminance error against the full model, e.g. 0.5% or 0.005")
      ->default_val("0.5%");
  choose->add_option("--max-tolerance", choose_max, "Daylight largest relative luminance error (outside a 1 deg aureole)")
      ->default_val("2%");
  choose->add_option("--twilight-tolerance", choose_twilight, "Twilight (sun zenith 92-100 deg) RMS relative luminance error")
      ->default_val("3%");
  choose->add_option("--method", ao.method, "Deterministic method: " + TextList(methods, ", "))->default_val("orders");

  CLI::App* fog = cli.app().add_subcommand(
      "fog", "Reference fog of the low atmosphere: GT7 fog LUT slices, depth tables, attenuation (docs/fog.md)");
  add_scene_options(fog);
  fog::FogRenderOptions fo;
  double cut_km = 1.0;
  std::string lut_size = "32x32", att_size = "64x64", lut_texels = "nodes", fog_shard;
  const std::string segment_methods = TextList(SegmentMethodNames(), ", ");
  fog->add_option("--method", fo.method, segment_methods + " (deterministic, all orders) or path (the Monte-Carlo reference)")
      ->default_val("orders");
  add_quality(fog, &fo.method_options.quality, segment_methods);
  fog->add_option("--spectral-stride", fo.method_options.spectral_stride,
                  "orders: run on every k-th wavelength (and the last), the transfer interpolated (docs/sky-methods.md)")
      ->default_val(1);
  fog->add_option("--cut-altitude-km", cut_km, "Top of the low atmosphere that scatters into the fog (km; docs/fog.md)")
      ->default_val(1.0);
  fog->add_option("--observer-altitude-m", fo.observer_altitude_m, "Override the atmosphere's observer altitude (m)");
  fog->add_option("--lut-size", lut_size, "Fog LUT slices on the GT7 sphere mapping, WxH")->default_val("32x32");
  fog->add_option("--time-mapping", fo.time_mapping, "GT7 time mapping of the slices: gt7, gt7-quadratic[:<upper>+<lower>]")
      ->default_val("gt7-quadratic");
  fog->add_option("--lut-texels", lut_texels,
                  std::string("Texel grid of the slices: ") + gt7::TexelGridName(gt7::TexelGrid::kNodes) +
                      " (default: x/(W-1), y/(H-1), a row at the zenith) or " + gt7::TexelGridName(gt7::TexelGrid::kCentres) +
                      " ((x+1/2)/W, lut-pack's; docs/fog.md)")
      ->default_val("nodes");
  fog->add_option("--sun-zenith-deg", fo.sun_zenith_deg, "Sun zenith angles of the depth tables (deg), comma separated")
      ->delimiter(',')->default_str("30,60,80,88,92,96");
  fog->add_option("--elevations", fo.elevations, "Depth tables: view elevations 90 (i/(m-1))^2 deg, i = 0..m-1")
      ->default_val(17);
  fog->add_option("--azimuths-deg", fo.azimuth_deg, "Depth tables: view azimuths from the sun (deg), comma separated")
      ->delimiter(',')->default_str("0,10,30,60,90,120,150,180");
  fog->add_option("--depths", fo.depths, "Depth tables: normalised depths (j/n)^3, j = 1..n")->default_val(32);
  fog->add_option("--attenuation-size", att_size, "Attenuation LUT nodes, WxH (u = depth^(1/3), v = elevation^(1/2))")
      ->default_val("64x64");
  fog->add_option("--shard", fog_shard,
                  "Render only shard K of N (K/N, 0 <= K < N): a contiguous range of the LUT slices, then the depth "
                  "tables (shard 0 also the transmittances), joined by sky-render merge into the unsharded bytes "
                  "(docs/cluster.md)");

  CLI::App* merge = cli.app().add_subcommand(
      "merge", "Join the shard files of one render (render or fog --shard K/N, every K) into the unsharded render's bytes");
  std::vector<std::string> merge_inputs;
  RenderOptions mo;
  std::string merge_ocio;
  merge->add_option("shards", merge_inputs, "The N shard EXRs, in any order")->required();
  merge->add_option("-o,--output", output, "Output file")->required();
  merge->add_option("--depfile", depfile, "Write a Make-style depfile of every file read");
  merge->add_option("--preview", mo.preview, "Also write the PNG preview render --preview writes");
  merge->add_option("--display", mo.display, "Preview display: sRGB, Rec.1886 Rec.709 or Rec.2100-PQ")->default_val("sRGB");
  merge->add_option("--white-cd-m2", mo.white, "Preview: luminance shown as white, or 'auto' per row")->default_val("auto");
  merge->add_option("--exposure", mo.exposure_stops, "Preview exposure in stops")->default_val(0.0);
  merge->add_option("--ocio-config", merge_ocio, "OCIO config of the preview (default: $SKYBAKE_OCIO or the repo's ocio/config.ocio)");

  return cli.Run(argc, argv, [&] {
    if (merge->parsed()) {
      const fs::path ocio = ColorConfig::ResolvePath(merge_ocio);
      if (!mo.preview.empty()) CheckPreviewOptions(ocio, mo);
      std::vector<ShardFile> shards;
      std::vector<fs::path> read;
      for (const std::string& f : merge_inputs) {
        shards.push_back({f, ReadExrParts(f)});
        read.push_back(f);
      }
      // The first shard file says the render's kind (fog or sky); a shard of the other kind is
      // refused by name (a file that is no shard at all, by the merge).
      auto is_shard = [](const ShardFile& f) {
        return std::any_of(f.parts.begin(), f.parts.end(), [](const ExrPart& p) { return p.name == kShardPart; });
      };
      const auto first = std::find_if(shards.begin(), shards.end(), is_shard);
      const ShardFile& kind_file = first == shards.end() ? shards.front() : *first;
      const bool fog_shards = fog::IsFogShard(kind_file.parts);
      for (const ShardFile& f : shards) {
        if (is_shard(f) && fog::IsFogShard(f.parts) != fog_shards) {
          throw InputError(FileLoc{f.path, 0}, fmt::format("a shard of a {} render, but {} is a shard of a {} render",
                                                           fog_shards ? "sky" : "fog", kind_file.path,
                                                           fog_shards ? "fog" : "sky"));
        }
      }
      if (fog_shards && !mo.preview.empty()) throw UsageError("--preview: a fog render has no preview");
      const std::vector<ExrPart> parts = fog_shards ? fog::MergeFogShards(shards) : MergeRenderShards(shards);
      WriteExrParts(output, parts);
      if (!mo.preview.empty()) {
        std::vector<std::vector<float>> slices;
        for (const ExrPart& p : parts) {
          if (p.name == "transmittance" || p.name == "sun" || p.name == "irradiance") continue;
          std::vector<float> rgb(static_cast<size_t>(p.image.width) * p.image.height * 3);
          const int channel[3] = {p.image.ChannelIndex("R"), p.image.ChannelIndex("G"), p.image.ChannelIndex("B")};
          for (size_t t = 0; t < rgb.size() / 3; ++t) {
            for (size_t c = 0; c < 3; ++c) {
              rgb[t * 3 + c] = p.image.pixels[t * p.image.channels.size() + static_cast<size_t>(channel[c])];
            }
          }
          slices.push_back(std::move(rgb));
        }
        WritePreviewOfReference(ocio, mo, parts.front().image.width, parts.front().image.height, slices, mo.preview);
        read.push_back(ocio);
      }
      cli.Info(fmt::format("{} shards merged", shards.size()));
      if (!depfile.empty()) WriteDepfile(depfile, output, read);
      return;
    }
    if (fog->parsed()) {
      auto size = [](const std::string& text, const char* opt, int* w, int* h) {
        const std::optional<Size2> s = ParseSize(text, 2, 4096);
        if (!s) throw UsageError(std::string(opt) + ": expected " + SizeExpected(2, 4096, "32x32") + ", got '" + text + "'");
        *w = s->width;
        *h = s->height;
      };
      size(lut_size, "--lut-size", &fo.lut_width, &fo.lut_height);
      size(att_size, "--attenuation-size", &fo.attenuation_width, &fo.attenuation_height);
      const std::optional<gt7::TexelGrid> grid = gt7::ParseTexelGrid(lut_texels);
      if (!grid) throw UsageError("--lut-texels: expected nodes or centres, got '" + lut_texels + "'");
      fo.texel_grid = *grid;
      if (!(cut_km > 0.0 && cut_km < 1e4)) throw UsageError("--cut-altitude-km: expected a positive altitude in km");
      fo.cut_altitude_m = cut_km * 1e3;
      if (!fog_shard.empty()) fo.shard = fog::ParseFogShard(fog_shard, fo);
      Scene s = LoadScene(scene, cli.Progress());
      const fog::FogRender r = fog::RenderFog(s, fo, cli.Progress());
      fog::WriteFogRender(s, fo, r, output, cli.name());
      const fog::FogShardRange own = fog::FogShardRangeOf(fo.shard, r.slice_zenith_deg.size(), r.tables.size());
      cli.Info(fmt::format("{} fog LUT slices, {} depth tables", own.slice_end - own.slice_begin,
                           own.table_end - own.table_begin));
      if (!depfile.empty()) WriteDepfile(depfile, output, s.files_read);
      return;
    }
    if (ro.sun_zenith_deg.empty()) ro.sun_zenith_deg = {30, 70, 85, 90, 94};
    if (po.wavelengths_nm.empty()) po.wavelengths_nm = {440, 550, 680};
    if (budget->parsed()) {
      if (bo.sun_zenith_deg.empty()) bo.sun_zenith_deg = {30, 70, 85, 90, 94};
      bo.tolerance = ParseTolerance(tolerance);
      if (!altitude_range.empty()) {
        double lo = 0.0, hi = 0.0;
        char tail = 0;
        if (std::sscanf(altitude_range.c_str(), "%lf:%lf%c", &lo, &hi, &tail) != 2 || lo < 0.0) {
          throw UsageError("--altitude-range-m: expected lo:hi in m (e.g. 0:300), got '" + altitude_range + "'");
        }
        bo.altitude_lo_m = lo;
        bo.altitude_hi_m = hi;
      }
      const BudgetReport rep = RunBudget(scene, bo, cli.Progress());
      WriteFileIfChanged(output, BudgetCsv(rep));
      std::fputs(BudgetTable(rep).c_str(), stdout);
      if (!depfile.empty()) WriteDepfile(depfile, output, rep.files_read);
      return;
    }
    if (choose->parsed()) {
      ao.tolerance_rms = ParseTolerance(choose_rms, "--tolerance");
      ao.tolerance_max = ParseTolerance(choose_max, "--max-tolerance");
      ao.twilight_tolerance_rms = ParseTolerance(choose_twilight, "--twilight-tolerance");
      const AutoQualityChoice ch = ChooseQuality(scene, ao, cli.Progress());
      WriteFileIfChanged(output, AutoQualityYaml(ch));
      std::fputs(AutoQualityTable(ch).c_str(), stdout);
      if (!depfile.empty()) WriteDepfile(depfile, output, ch.files_read);
      return;
    }
    std::vector<fs::path> extra_read;
    if (render->parsed() && settings_opt->count() > 0) {
      for (const char* o : {"--quality", "--spectral-stride"}) {
        if (render->count(o) > 0) throw UsageError(std::string(o) + ": not with --settings (the file says it)");
      }
      const AutoQualitySettings set = ReadAutoQualitySettings(settings_file);
      if (render->count("--method") > 0 && ro.method != set.method) {
        throw UsageError(fmt::format("--method {}: {} is a choice for method {}", ro.method, settings_file, set.method));
      }
      ro.method = set.method;
      ro.method_options.quality = set.quality;
      ro.method_options.spectral_stride = set.stride;
      ro.quality_choice = set.provenance;
      extra_read.push_back(settings_file);
    }
    // Load and validate (every input file is recorded for the depfile).
    Scene s = LoadScene(scene, cli.Progress());
    s.files_read.insert(s.files_read.end(), extra_read.begin(), extra_read.end());
    if (render->parsed() && !ro.preview.empty()) CheckPreviewOptions(s, ro);
    if (render->parsed()) {
      RenderProducts p = RenderProductsOf(s, ro, cli.Progress());
      WriteRender(s, ro, p, output, cli.name());
      if (!ro.preview.empty()) WriteRenderPreview(s, ro, p, ro.preview);
      cli.Info(fmt::format("{} sun angles, {} paths", p.sky.slices.size(), p.sky.total_paths));
    } else {
      WritePoints(s, po, output, cli.Progress());
    }
    if (!depfile.empty()) WriteDepfile(depfile, output, s.files_read);
  });
}
