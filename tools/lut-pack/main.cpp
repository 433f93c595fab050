// lut-pack: GT7 adaptive sky LUTs and the other runtime textures from sky-render products
// (docs/lut-pack.md).
//
//   lut-pack pack NAME=SKY.exr ... -o OUT/report.json [--sky-exposure-stops auto|N] [--budget-mib 3.5]
//            [--night-end-zenith-deg 108] [--ocio-config config.ocio] [--depfile OUT/report.json.d]
//       SKY.exr: sky-render render --mapping gt7 --time-mapping gt7 --size WxH (one per basis sky);
//       writes OUT/sky_<NAME>.{ktx2,_array.ktx2,dds,exr}, OUT/{transmittance,sun,ambient}.{ktx2,dds},
//       OUT/other_luts.exr, OUT/contact_sheet.png and the report.
//   lut-pack check LUT.ktx2[:WEIGHT] ... --direct DIRECT.exr -o check.json [--sun-cone-deg 5]
//       decodes the LUT (or the weighted blend of several) at the direct render's sun angles and
//       directions and reports the luminance error.
//   lut-pack decode LUT.ktx2[:WEIGHT] ... --sun-zenith-deg 30,70 --size 64x32 -o dome.exr
//       the decoded sky (or blend) on upper-hemisphere domes (lut/dome_view.h), one per sun angle,
//       stacked vertically: the reference the runtime shader is checked against (docs/runtime.md).
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <set>

#include <fmt/format.h>

#include "color/color.h"
#include "io/cli.h"
#include "io/error.h"
#include "io/fileio.h"
#include "io/png.h"
#include "io/png_label.h"
#include "io/yaml.h"
#include "lut/check.h"
#include "lut/decoder.h"
#include "lut/dome_view.h"
#include "lut/ktx2.h"
#include "lut/sky_lut.h"
#include "outputs.h"
#include "report.h"
#include "io/size.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {

bool IsSkyName(const std::string& s) {
  if (s.empty() || !std::islower(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s) {
    if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_')) return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("lut-pack",
              "Packs GT7 adaptive sky LUTs (R11G11B10F; KTX2 3D and 2D array, DDS, EXR for inspection) and the\n"
              "transmittance, sun and ambient LUTs from sky-render products, and checks decoded LUTs against direct\n"
              "renders. See docs/lut-pack.md.");
  cli.app().require_subcommand(1);
  cli.app().fallthrough();
  std::string output, depfile, ocio_config;

  CLI::App* pack = cli.app().add_subcommand("pack", "Pack the basis skies of one set (one NAME=render.exr per sky)");
  std::vector<std::string> inputs;
  std::string exposure_stops = "auto";
  double budget_mib = 3.5, night_end_deg = 108.0;
  pack->add_option("skies", inputs, "NAME=SKY.exr: a basis sky's name and its sky-render render (--mapping gt7 --time-mapping gt7)")
      ->required();
  pack->add_option("-o,--output", output, "The report (JSON); the textures are written beside it")->required();
  pack->add_option("--sky-exposure-stops", exposure_stops,
                   "Sky texels store cd/m^2 x 2^N; auto: per texture the largest 2^-k (k >= 0) with which nothing clamps "
                   "(docs/lut-pack.md 'Scale')")
      ->default_val("auto");
  pack->add_option("--budget-mib", budget_mib, "Fail when the sky LUTs' texels exceed this many MiB (GT7: 3.5)")
      ->default_val(3.5)->check(CLI::Range(1e-6, 1e6));
  pack->add_option("--night-end-zenith-deg", night_end_deg, "Sun zenith angle where the sky reaches its night constant")
      ->default_val(108.0)->check(CLI::Range(100.0, 180.0));
  pack->add_option("--ocio-config", ocio_config, "OCIO config (default: $SKYBAKE_OCIO or the repo's ocio/config.ocio)");
  pack->add_option("--depfile", depfile, "Write a Make-style depfile of every file read");

  CLI::App* check = cli.app().add_subcommand("check", "Decode LUTs at a direct render's sun angles and compare");
  std::vector<std::string> luts;
  std::string direct, check_out;
  double sun_cone_deg = 5.0;
  check->add_option("luts", luts, "LUT.ktx2 or LUT.ktx2:WEIGHT (several: the weighted blend)")->required();
  check->add_option("--direct", direct, "sky-render render (equirectangular or fisheye) of the same or the blended atmosphere")
      ->required();
  check->add_option("-o,--output", check_out, "Figures (JSON)")->required();
  check->add_option("--sun-cone-deg", sun_cone_deg, "Also report the errors outside this cone around the sun")
      ->default_val(5.0)->check(CLI::Range(0.0, 180.0));
  check->add_option("--ocio-config", ocio_config, "OCIO config (default: $SKYBAKE_OCIO or the repo's ocio/config.ocio)");
  std::string interp = "geometric";
  check->add_option("--time-interpolation", interp, "Blend of neighbouring slices: geometric (default) or linear (the talk's lerp)")
      ->check(CLI::IsMember({"geometric", "linear"}));

  CLI::App* decode = cli.app().add_subcommand("decode", "Decode LUTs (or a weighted blend) on upper-hemisphere domes");
  std::vector<std::string> decode_luts;
  std::vector<double> decode_sza;
  std::string decode_out, decode_size = "64x32";
  decode->add_option("luts", decode_luts, "LUT.ktx2 or LUT.ktx2:WEIGHT (several: the weighted blend sum_k w_k L_k)")->required();
  decode->add_option("--sun-zenith-deg", decode_sza, "Sun zenith angles (deg, 0-180), comma separated")
      ->delimiter(',')->required();
  decode->add_option("--size", decode_size, "Dome size WxH (azimuth x zenith angle 0-90 deg)")->default_val("64x32");
  decode->add_option("-o,--output", decode_out, "The domes (EXR: R, G, B Linear Rec.2020 cd/m^2, one W x H dome per sun angle, stacked)")
      ->required();
  decode->add_option("--time-interpolation", interp, "Blend of neighbouring slices: geometric (default) or linear (the talk's lerp)")
      ->check(CLI::IsMember({"geometric", "linear"}));
  std::string decode_preview;
  double decode_white = 0.0;
  decode->add_option("--preview", decode_preview, "Also write the domes through the OCIO sRGB display view as a PNG");
  decode->add_option("--white-cd-m2", decode_white, "The preview's white: the luminance shown as display white (cd/m^2)")
      ->check(CLI::PositiveNumber);
  decode->add_option("--ocio-config", ocio_config, "OCIO config (default: $SKYBAKE_OCIO or the repo's ocio/config.ocio)");

  // LUT.ktx2[:WEIGHT] -> path and weight (UsageError otherwise).
  auto split_weighted = [](const std::string& l) {
    std::string path = l;
    double w = 1.0;
    const size_t colon = l.rfind(':');
    if (colon != std::string::npos && colon > 0) {
      try {
        size_t used = 0;
        w = std::stod(l.substr(colon + 1), &used);
        if (used != l.size() - colon - 1) throw std::invalid_argument("trailing");
        path = l.substr(0, colon);
      } catch (const std::exception&) {
        throw UsageError("expected LUT.ktx2 or LUT.ktx2:WEIGHT, got '" + l + "'");
      }
      if (!std::isfinite(w)) throw UsageError("the weight of '" + l + "' must be a finite number");
    }
    return std::pair<std::string, double>{path, w};
  };

  return cli.Run(argc, argv, [&] {
    if (decode->parsed()) {
      if (!decode_preview.empty() && !(decode_white > 0.0 && std::isfinite(decode_white))) {
        throw UsageError("--preview needs --white-cd-m2 with a finite positive luminance");
      }
      const std::optional<Size2> dome_size = ParseSize(decode_size, 1, 8192);
      if (!dome_size) throw UsageError("--size: expected " + SizeExpected(1, 8192, "64x32") + ", got '" + decode_size + "'");
      const int w = dome_size->width, h = dome_size->height;
      for (double z : decode_sza) {
        if (!(z >= 0.0 && z <= 180.0)) throw UsageError(fmt::format("--sun-zenith-deg: {} is not in 0-180", z));
      }
      std::vector<lut::SkyLutDecoder> decoders;
      std::vector<double> weights;
      decoders.reserve(decode_luts.size());
      for (const std::string& l : decode_luts) {
        const auto [path, weight] = split_weighted(l);
        decoders.push_back(lut::SkyLutDecoder::FromKtx2(ktx2::ReadKtx2(path), path));
        decoders.back().set_time_interpolation(interp == "linear" ? lut::TimeInterpolation::kLinear : lut::TimeInterpolation::kGeometric);
        weights.push_back(weight);
      }
      std::vector<std::pair<const lut::SkyLutDecoder*, double>> weighted;
      for (size_t i = 0; i < decoders.size(); ++i) weighted.emplace_back(&decoders[i], weights[i]);
      ExrImage img;
      img.Resize(w, h * static_cast<int>(decode_sza.size()), {"R", "G", "B"});
      for (size_t k = 0; k < decode_sza.size(); ++k) {
        const std::vector<float> dome = lut::DecodeDome(weighted, decode_sza[k] * std::numbers::pi / 180.0, w, h);
        std::copy(dome.begin(), dome.end(), img.pixels.begin() + static_cast<long>(k * dome.size()));
      }
      std::string list, desc;
      for (double z : decode_sza) list += (list.empty() ? "" : " ") + FormatExact(z);
      for (const std::string& l : decode_luts) desc += (desc.empty() ? "" : " + ") + l;
      img.strings["skybake.quantity"] = "decoded sky radiance (lut/decoder.h, " + interp + " time interpolation) of " + desc;
      img.strings["skybake.unit"] = "cd/m^2, Linear Rec.2020";
      img.strings["skybake.mapping"] =
          "dome (lut/dome_view.h): W x H per sun angle, stacked vertically in the order of skybake.sun_zenith_deg; azimuth "
          "from the sun 2 pi (x + 1/2)/W - pi, view zenith (pi/2)(y + 1/2)/H";
      img.strings["skybake.sun_zenith_deg"] = list;
      Provenance prov;
      prov.tool = cli.name();
      prov.parameters = fmt::format("subcommand: decode\nluts: {}\nsun_zenith_deg: [{}]\nsize: {}\ntime_interpolation: {}\n", desc, list,
                                    decode_size, interp);
      for (const std::string& l : decode_luts) prov.AddInput(split_weighted(l).first);
      SetProvenance(img, prov);
      std::string png;
      if (!decode_preview.empty()) {
        const ColorConfig config = ColorConfig::Load(ocio_config);
        const ColorProcessor view = config.Display(ocio_names::kLinearRec2020, DisplayView{.white_cd_m2 = decode_white});
        std::vector<float> rgb(img.pixels);
        png = EncodePng8(img.width, img.height, 3, EncodePreview8(img.width, img.height, rgb, view));
      }
      WriteExr(decode_out, img);
      if (!decode_preview.empty()) WriteFileIfChanged(decode_preview, png);
      cli.Info(fmt::format("{} dome{} of {}x{} for {}", decode_sza.size(), decode_sza.size() == 1 ? "" : "s", w, h, desc));
      return;
    }
    if (pack->parsed()) {
      // Parse and validate the inputs.
      std::vector<std::pair<std::string, fs::path>> named;
      std::set<std::string> names;
      for (const std::string& in : inputs) {
        const size_t eq = in.find('=');
        if (eq == std::string::npos || !IsSkyName(in.substr(0, eq)) || eq + 1 == in.size()) {
          throw UsageError("expected NAME=SKY.exr with NAME a lowercase identifier (a-z, 0-9, _), got '" + in + "'");
        }
        if (!names.insert(in.substr(0, eq)).second) throw UsageError("basis sky '" + in.substr(0, eq) + "' is given twice");
        named.emplace_back(in.substr(0, eq), in.substr(eq + 1));
      }
      std::vector<lut::SkyRender> renders;
      renders.reserve(named.size());
      for (const auto& [name, path] : named) renders.push_back(lut::ReadSkyRender(path));
      const ColorConfig config = ColorConfig::Load(ocio_config);
      const Font font = Font::Load();  // the contact sheet's labels; missing: exit 1 before any output
      std::vector<fs::path> files_read;
      for (const auto& [name, path] : named) files_read.push_back(path);
      files_read.push_back(config.path());

      // One core call.
      std::vector<std::pair<std::string, const lut::SkyRender*>> set_in;
      for (size_t i = 0; i < named.size(); ++i) set_in.emplace_back(named[i].first, &renders[i]);
      lut::LutSetOptions opt;
      if (exposure_stops != "auto") {
        int stops = 0;
        auto [end, ec] = std::from_chars(exposure_stops.data(), exposure_stops.data() + exposure_stops.size(), stops);
        if (ec != std::errc() || end != exposure_stops.data() + exposure_stops.size() || stops < -24 || stops > 24) {
          throw UsageError("--sky-exposure-stops: expected auto or a whole number of stops from -24 to 24, got '" +
                           exposure_stops + "'");
        }
        opt.sky_scale = std::ldexp(1.0, stops);
      }
      opt.night_end_zenith_deg = night_end_deg;
      const lut::LutSet set = lut::BuildLutSet(set_in, opt, config, &files_read);
      {  // each file once, in first-read order (the CMF table is read once per basis sky)
        std::vector<fs::path> unique;
        for (const fs::path& f : files_read) {
          if (std::find(unique.begin(), unique.end(), f) == unique.end()) unique.push_back(f);
        }
        files_read = std::move(unique);
      }
      size_t sky_bytes = 0;
      for (const lut::SkyLutProduct& s : set.skies) sky_bytes += s.sky.bytes.size();
      const double budget_bytes = budget_mib * 1024.0 * 1024.0;
      if (static_cast<double>(sky_bytes) > budget_bytes) {
        throw UsageError(fmt::format("--budget-mib {}: the {} sky LUTs take {} bytes ({:.4f} MiB)", budget_mib,
                                     set.skies.size(), sky_bytes, sky_bytes / (1024.0 * 1024.0)));
      }

      // Encode everything in memory, then write.
      Provenance prov;
      prov.tool = cli.name();
      std::string params = fmt::format("sky_exposure_stops: {}\nbudget_mib: {}\nnight_end_zenith_deg: {}\nskies:\n",
                                       exposure_stops, FormatExact(budget_mib), FormatExact(night_end_deg));
      for (const auto& [name, path] : named) params += "  - " + name + "\n";
      prov.parameters = params;
      for (const fs::path& f : files_read) prov.AddInput(f);
      std::map<std::string, Provenance> sky_prov;
      for (const auto& [name, path] : named) {
        Provenance& sp = sky_prov[name];
        sp.tool = prov.tool;
        sp.parameters = fmt::format("sky_exposure_stops: {}\nnight_end_zenith_deg: {}\nbasis_sky: {}\n", exposure_stops,
                                    FormatExact(night_end_deg), name);
        sp.AddInput(path);
        for (size_t i = named.size(); i < files_read.size(); ++i) sp.AddInput(files_read[i]);  // OCIO config, CMFs
      }
      std::map<std::string, std::string> files = luttool::EncodeLutSet(set, prov, sky_prov, config, font);
      files["display.json"] = luttool::DisplayShaderJson(config);
      luttool::ReportContext ctx;
      for (const auto& [name, bytes] : files) ctx.file_bytes[name] = bytes.size();
      ctx.budget_bytes = budget_bytes;
      ctx.sky_texel_bytes = sky_bytes;
      ctx.ocio_config = config.path().filename().string();
      const std::string report = luttool::PackReportJson(set, ctx);
      const fs::path dir = fs::path(output).parent_path();
      int changed = 0;
      for (const auto& [name, bytes] : files) changed += WriteFileIfChanged(dir / name, bytes) ? 1 : 0;
      changed += WriteFileIfChanged(output, report) ? 1 : 0;
      if (!depfile.empty()) {
        std::vector<fs::path> deps = files_read;
        deps.push_back(font.path());  // not in the provenance: only the contact sheet depends on it
        WriteDepfile(depfile, output, deps);
      }
      cli.Info(fmt::format("{} skies, {} bytes of sky LUTs ({:.3f} MiB); {} of {} files changed", set.skies.size(), sky_bytes,
                           sky_bytes / (1024.0 * 1024.0), changed, files.size() + 1));
      return;
    }
    // check
    std::vector<lut::SkyLutDecoder> decoders;
    std::vector<double> weights;
    decoders.reserve(luts.size());
    for (const std::string& l : luts) {
      const auto [path, w] = split_weighted(l);
      decoders.push_back(lut::SkyLutDecoder::FromKtx2(ktx2::ReadKtx2(path), path));
      weights.push_back(w);
    }
    std::vector<std::pair<const lut::SkyLutDecoder*, double>> weighted;
    for (size_t i = 0; i < decoders.size(); ++i) {
      decoders[i].set_time_interpolation(interp == "linear" ? lut::TimeInterpolation::kLinear : lut::TimeInterpolation::kGeometric);
      weighted.emplace_back(&decoders[i], weights[i]);
    }
    const ColorConfig config = ColorConfig::Load(ocio_config);
    const lut::CheckResult r = lut::CheckAgainstDirect(weighted, direct, config, sun_cone_deg);
    std::string desc;
    for (const std::string& l : luts) desc += (desc.empty() ? "" : " + ") + l;
    WriteFileIfChanged(check_out, luttool::CheckReportJson(r, desc + " (" + interp + " time interpolation)"));
    for (const lut::CheckSlice& s : r.slices) {
      cli.Info(fmt::format("sun zenith {:.4f} deg (slice {:.3f}): RMS {:.3f} % upper ({:.3f} % outside {} deg of the sun), "
                           "{:.3f} % lower; max {:+.2f} % at view zenith {:.2f}, azimuth {:.1f}, {:.2f} deg from the sun",
                           s.sun_zenith_deg, s.slice_coordinate, 100 * s.rms_upper, 100 * s.rms_upper_outside_cone,
                           FormatExact(sun_cone_deg), 100 * s.rms_lower, 100 * s.max_upper.error, s.max_upper.view_zenith_deg,
                           s.max_upper.azimuth_deg, s.max_upper.sun_angle_deg));
    }
  });
}
