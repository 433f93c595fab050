// fog-fit: GT7 global fog from a reference fog render (docs/fog.md).
//
//   fog-fit fit FOG.exr -o OUT/fog_<sky>.json [--angle path|elevation] [--channels rgb|luminance]
//           [--params per-slice-elevation|per-slice|global] [--fit-sun-zenith-deg 30,60,...]
//           [--fit-elevation-stride N]
//           [--name SKY] [--ocio-config config.ocio] [--depfile OUT/fog_<sky>.json.d]
//       FOG.exr: sky-render fog (one basis sky). Fits a and p of
//       Fog = LUT(dir) (1 - exp(-a theta^p x)) / (1 - exp(-a theta^p)) for the fog and the shadowed fog
//       (per slice and elevation, per slice or global: --params), packs the fog, shadowed fog and
//       attenuation LUTs (R11G11B10F KTX2 3D + 2D array, DDS, EXR) and the parameter texture, and
//       writes the parameters (-o), the residual report and residual maps beside it.
//   fog-fit eval fog_<sky>.json --points in.csv -o out.csv
//       the reference evaluator: fog and transmittance for explicit directions, depths and sun angles.
#include <algorithm>
#include <cctype>
#include <filesystem>

#include <fmt/format.h>

#include "color/color.h"
#include "fog/fog_evaluator.h"
#include "fog/fog_luts.h"
#include "fog/fog_render.h"
#include "io/cli.h"
#include "io/csv.h"
#include "io/error.h"
#include "io/fileio.h"
#include "io/yaml.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

bool IsName(const std::string& s) {
  if (s.empty() || !std::islower(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_';
  });
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("fog-fit",
              "GT7 global fog from a reference fog render (sky-render fog): fits the depth function\n"
              "Fog = LUT(dir) (1 - exp(-a theta^p x)) / (1 - exp(-a theta^p)) (a, p per fog LUT slice, a also per\n"
              "elevation by default), packs the fog, shadowed fog, attenuation and parameter textures and reports\n"
              "the model's error; `eval` runs the reference evaluator. See docs/fog.md.");
  cli.app().require_subcommand(1);
  cli.app().fallthrough();
  std::string output, depfile, ocio_config;

  CLI::App* fit = cli.app().add_subcommand("fit", "Fit, pack and measure one basis sky's fog");
  std::string input, name, angle = "path", channels = "rgb", params_mode = "per-slice-elevation";
  std::vector<double> fit_sza;
  int fit_elevation_stride = 1;
  fit->add_option("render", input, "FOG.exr: sky-render fog of one basis sky")->required();
  fit->add_option("-o,--output", output, "The parameter file OUT/PREFIX.json; the other products are written beside it")
      ->required();
  fit->add_option("--name", name, "Basis sky name in the products (default: the render's atmosphere)");
  fit->add_option("--angle", angle, "Normalised angle theta of the depth function: path (default) or elevation (the talk's)")
      ->default_val("path");
  fit->add_option("--channels", channels, "rgb: a, p per Linear Rec.2020 channel (default); luminance: one a, p for all")
      ->default_val("rgb");
  fit->add_option("--params", params_mode,
                  std::string("Where a, p live: ") + fog::ParamModeName(fog::ParamMode::kPerSliceElevation) +
                      " (default: per slice of the fog LUT, a also per elevation node), " +
                      fog::ParamModeName(fog::ParamMode::kPerSlice) +
                      " (per slice: fitted per depth table, interpolated in the sun angle) or " +
                      fog::ParamModeName(fog::ParamMode::kGlobal) + " (one pair per channel: the talk's model); docs/fog.md")
      ->default_val(fog::ParamModeName(fog::ParamMode::kPerSliceElevation));
  fit->add_option("--fit-elevation-stride", fit_elevation_stride,
                  "Fit on every N-th elevation row of the depth tables (and the last; default 1: all); errors are measured on all")
      ->default_val(1);
  fit->add_option("--fit-sun-zenith-deg", fit_sza,
                  "Fit on these depth tables only (sun zenith, deg, comma separated; default all); errors are measured on all")
      ->delimiter(',');
  fit->add_option("--ocio-config", ocio_config, "OCIO config (default: $SKYBAKE_OCIO or the repo's ocio/config.ocio)");
  fit->add_option("--depfile", depfile, "Write a Make-style depfile of every file read");

  CLI::App* eval = cli.app().add_subcommand("eval", "The reference evaluator at explicit points (CSV in, CSV out)");
  std::string params, points, eval_out;
  eval->add_option("params", params, "fog_<sky>.json written by fog-fit fit")->required();
  eval->add_option("--points", points,
                   "CSV: sun_zenith_deg, view_zenith_deg, relative_azimuth_deg, depth_m[, occlusion]")
      ->required();
  eval->add_option("-o,--output", eval_out, "Output CSV")->required();
  eval->add_option("--depfile", depfile, "Write a Make-style depfile of every file read");

  return cli.Run(argc, argv, [&] {
    if (fit->parsed()) {
      fog::FogFitOptions o;
      const std::optional<fog::AngleDefinition> a = fog::ParseAngleDefinition(angle);
      if (!a) throw UsageError("--angle: expected path or elevation, got '" + angle + "'");
      o.angle = *a;
      if (channels != "rgb" && channels != "luminance") throw UsageError("--channels: expected rgb or luminance, got '" + channels + "'");
      o.per_channel = channels == "rgb";
      const std::optional<fog::ParamMode> pm = fog::ParseParamMode(params_mode);
      if (!pm) throw UsageError("--params: expected per-slice-elevation, per-slice or global, got '" + params_mode + "'");
      o.params = *pm;
      o.fit_sun_zenith_deg = fit_sza;
      if (fit_elevation_stride < 1) throw UsageError("--fit-elevation-stride: expected a whole number >= 1");
      o.fit_elevation_stride = fit_elevation_stride;
      const std::string file = fs::path(output).filename().string();
      if (file.size() <= 5 || file.substr(file.size() - 5) != ".json") {
        throw UsageError("-o: expected OUT/PREFIX.json (the other products are named PREFIX_*), got '" + output + "'");
      }
      const std::string prefix = file.substr(0, file.size() - 5);
      if (!IsName(prefix)) throw UsageError("-o: PREFIX must be a lowercase identifier (a-z, 0-9, _), got '" + prefix + "'");

      const fog::FogRender render = fog::ReadFogRender(input);
      if (name.empty()) name = render.atmosphere;
      if (!IsName(name)) throw UsageError("--name: expected a lowercase identifier (a-z, 0-9, _), got '" + name + "'");
      const ColorConfig config = ColorConfig::Load(ocio_config);
      const Font font = Font::Load();  // the residual PNG's labels; missing: exit 1 before any output
      std::vector<fs::path> files_read = {input, config.path()};

      const fog::FogProducts products = fog::BuildFogProducts(render, name, o, config, &files_read);

      Provenance prov;
      prov.tool = cli.name();
      std::string fit_list;
      for (double z : fit_sza) fit_list += (fit_list.empty() ? "" : ", ") + FormatExact(z);
      prov.parameters = fmt::format("subcommand: fit\nname: {}\nangle: {}\nchannels: {}\nparams: {}\nfit_sun_zenith_deg: [{}]\nfit_elevation_stride: {}\nprefix: {}\n",
                                    name, angle, channels, params_mode, fit_list, fit_elevation_stride, prefix);
      for (const fs::path& f : files_read) prov.AddInput(f);
      const std::map<std::string, std::string> files = fog::EncodeFogProducts(render, products, prefix, prov, font);
      const fs::path dir = fs::path(output).parent_path();
      int changed = 0;
      for (const auto& [f, bytes] : files) {
        if (f != file) changed += WriteFileIfChanged(dir / f, bytes) ? 1 : 0;
      }
      changed += WriteFileIfChanged(output, files.at(file)) ? 1 : 0;  // the edge's output last
      if (!depfile.empty()) {
        std::vector<fs::path> deps = files_read;
        deps.push_back(font.path());  // not in the provenance: only the residual PNG depends on it
        WriteDepfile(depfile, output, deps);
      }
      const fog::ProductStats& s = products.fog_eval;
      cli.Info(fmt::format("{}: fog ({} parameters) a = {:.4g} {:.4g} {:.4g}, p = {:.4g} {:.4g} {:.4g} (global fit); evaluator error RMS {:.2f} % "
                           "(max {:.1f} %), near the camera {:.2f} % (max {:.1f} %), horizon {:.2f} % (max {:.1f} %); "
                           "{} of {} files changed",
                           name, params_mode, products.params.a[0], products.params.a[1], products.params.a[2], products.params.p[0],
                           products.params.p[1], products.params.p[2], 100 * s.all.rms, 100 * s.all.max, 100 * s.near.rms,
                           100 * s.near.max, 100 * s.horizon.rms, 100 * s.horizon.max, changed, files.size()));
      return;
    }
    // eval
    std::vector<fs::path> files_read;
    const fog::FogEvaluator ev = fog::FogEvaluator::Load(params, &files_read);
    const CsvTable csv = CsvTable::Load(points);
    files_read.push_back(points);
    Diagnostics d;
    const std::vector<double> sza = csv.Numbers("sun_zenith_deg", d), vza = csv.Numbers("view_zenith_deg", d),
                              raz = csv.Numbers("relative_azimuth_deg", d), depth = csv.Numbers("depth_m", d);
    std::vector<double> occ(csv.rows(), 0.0);
    if (csv.ColumnIndex("occlusion") >= 0) occ = csv.Numbers("occlusion", d);
    for (size_t r = 0; r < csv.rows() && d.empty(); ++r) {
      if (!(sza[r] >= 0 && sza[r] <= 180)) d.Add(csv.LocOfRow(r), "sun_zenith_deg must be in 0-180");
      if (!(vza[r] >= 0 && vza[r] <= 180)) d.Add(csv.LocOfRow(r), "view_zenith_deg must be in 0-180");
      if (!(depth[r] >= 0)) d.Add(csv.LocOfRow(r), "depth_m must be >= 0");
      if (!(occ[r] >= 0 && occ[r] <= 1)) d.Add(csv.LocOfRow(r), "occlusion must be in 0-1");
    }
    d.ThrowIfAny();
    std::string out = "# source: fog-fit eval (the reference evaluator, docs/fog.md) of " + fs::path(params).filename().string() +
                      "; radiance in cd/m^2 (Linear Rec.2020), transmittance per channel (1)\n"
                      "sun_zenith_deg,view_zenith_deg,relative_azimuth_deg,depth_m,occlusion,x,theta,"
                      "fog_R_cd_m2,fog_G_cd_m2,fog_B_cd_m2,transmittance_R,transmittance_G,transmittance_B\n";
    for (size_t r = 0; r < csv.rows(); ++r) {
      const double t = vza[r] * kDeg, p = raz[r] * kDeg;
      const std::array<double, 3> dir{std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
      const fog::FogValue v = ev.Evaluate(dir, depth[r], sza[r] * kDeg, occ[r]);
      out += fmt::format("{},{},{},{},{},{:.9g},{:.9g},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}\n", FormatExact(sza[r]),
                         FormatExact(vza[r]), FormatExact(raz[r]), FormatExact(depth[r]), FormatExact(occ[r]), v.x, v.theta,
                         v.inscattered[0], v.inscattered[1], v.inscattered[2], v.transmittance[0], v.transmittance[1],
                         v.transmittance[2]);
    }
    WriteFileIfChanged(eval_out, out);
    if (!depfile.empty()) WriteDepfile(depfile, eval_out, files_read);
  });
}
