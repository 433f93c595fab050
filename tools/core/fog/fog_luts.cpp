#include "fog/fog_luts.h"

#include "fog/fog_errors.h"
#include "fog/fog_parameters.h"
#include "fog/fog_reference.h"

namespace fs = std::filesystem;

namespace skybake::fog {

namespace {

// The slices' mappings, as lut-pack's sky LUTs describe them (for lut::SkyKtx2 and the decoder).
lut::SkyRender LayoutOf(const FogRender& render) {
  lut::SkyRender lay;
  lay.path = render.path;
  lay.width = render.lut_width;
  lay.height = render.lut_height;
  lay.time = render.time;
  lay.time_mapping_name = render.time_mapping_name;
  lay.sphere = render.sphere;
  lay.slice_zenith_deg = render.slice_zenith_deg;
  lay.observer = render.observer;
  lay.method = render.method;
  return lay;
}

// W x H x slices of CIE-XYZ-D65 -> Linear Rec.2020, packed as lut-pack packs a sky (R11G11B10F,
// automatic power-of-two scale).
lut::PackedTexture PackSlices(const FogRender& render, const std::vector<std::vector<float>>& slices,
                              const ColorProcessor& to2020, const ColorProcessor& to_xyz) {
  std::vector<float> rgb;
  for (const std::vector<float>& s : slices) rgb.insert(rgb.end(), s.begin(), s.end());
  to2020.Apply(rgb);
  const int n_slices = static_cast<int>(render.slice_zenith_deg.size());
  return lut::PackRgb(render.lut_width, render.lut_height, n_slices, rgb, lut::AutomaticScale(rgb), to_xyz);
}

// The attenuation LUT: the sunlight-weighted transmittance at each node of the render's
// attenuation grid, Linear Rec.2020.
lut::PackedTexture PackAttenuation(const FogRender& render, const SunlightTransmittance& sunlight, const ColorProcessor& to_xyz) {
  std::vector<float> rgb;
  const size_t nw = sunlight.wavelengths();
  const size_t nodes = static_cast<size_t>(render.attenuation_width) * render.attenuation_height;
  for (size_t q = 0; q < nodes; ++q) {
    const std::array<float, 3> c = sunlight(&render.attenuation[q * nw]);
    rgb.insert(rgb.end(), c.begin(), c.end());
  }
  return lut::PackRgb(render.attenuation_width, render.attenuation_height, 1, rgb, lut::AutomaticScale(rgb), to_xyz);
}

}  // namespace

const char* ParamModeName(ParamMode m) {
  switch (m) {
    case ParamMode::kGlobal:
      return "global";
    case ParamMode::kPerSlice:
      return "per-slice";
    case ParamMode::kPerSliceElevation:
      return "per-slice-elevation";
  }
  return "?";
}

std::optional<ParamMode> ParseParamMode(const std::string& name) {
  for (ParamMode m : {ParamMode::kGlobal, ParamMode::kPerSlice, ParamMode::kPerSliceElevation}) {
    if (name == ParamModeName(m)) return m;
  }
  return std::nullopt;
}

FogEvaluator MakeEvaluator(const FogProducts& p) {
  const lut::SkyRender& r = p.layout;
  lut::SkyLutDecoder fog(r.width, r.height, r.time, r.sphere, p.fog.decoded_rgb, {0, 0, 0}, p.options.night_end_zenith_deg);
  lut::SkyLutDecoder sh(r.width, r.height, r.time, r.sphere, p.shadowed.decoded_rgb, {0, 0, 0}, p.options.night_end_zenith_deg);
  fog.set_texel_grid(p.texel_grid);
  sh.set_texel_grid(p.texel_grid);
  AttenuationLut att(p.attenuation.width, p.attenuation.height, p.attenuation.decoded_rgb);
  return FogEvaluator(p.params, std::move(fog), std::move(sh), std::move(att));
}

FogProducts BuildFogProducts(const FogRender& render, const std::string& sky, const FogFitOptions& o,
                             const ColorConfig& config, std::vector<fs::path>* files_read) {
  FogProducts out;
  out.sky = sky;
  out.options = o;
  const ColorProcessor to2020 = config.Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  const FogReference ref = MakeFogReference(render, o, to2020, LuminanceRow(to_xyz));

  FitFogParameters(ref, sky, &out);

  out.layout = LayoutOf(render);
  out.texel_grid = render.texel_grid;
  out.fog = PackSlices(render, render.slice_xyz, to2020, to_xyz);
  out.shadowed = PackSlices(render, render.slice_shadowed_xyz, to2020, to_xyz);
  const SunlightTransmittance sunlight(render, config, files_read);
  out.attenuation = PackAttenuation(render, sunlight, to_xyz);

  // Errors: the fit with the reference at x = 1, and the evaluator on the packed textures.
  const FogEvaluator eval = MakeEvaluator(out);
  MeasureFogErrors(ref, eval, &out);
  AddFitDiagnostics(ref, &out);
  MeasureAttenuation(ref, eval, sunlight, &out);
  return out;
}

}  // namespace skybake::fog
