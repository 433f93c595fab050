// fog-fit's core (docs/fog.md): a reference fog render (fog/fog_render.h) of one basis sky ->
//   - the fit of GT7's depth function (fog/fog_fit.h) for the fog and the shadowed fog, per
//     Linear Rec.2020 channel (or one fit on luminance for all three);
//   - the runtime textures, packed as lut-pack packs the sky (lut/sky_lut.h PackRgb: R11G11B10F,
//     automatic power-of-two scale): the fog LUT and the shadowed fog LUT (W x H x N slices of the
//     GT7 sphere and time mappings, readable by lut::SkyLutDecoder) and the attenuation LUT
//     (64 x 64, u = x^(1/3), v = elevation^(1/2));
//   - the error of the model against the reference over every direction and depth of the depth
//     tables, twice: "fit" (the model with the exact x = 1 fog: the depth function's own error) and
//     "evaluator" (fog/fog_evaluator.h on the packed textures: what a game gets), as RMS and max
//     relative luminance error over subsets (all, near the camera, at the horizon, ...), with
//     residual maps.
// Deterministic: statistics are accumulated serially in table order.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "color/color.h"
#include "fog/fog_evaluator.h"
#include "fog/fog_fit.h"
#include "fog/fog_render.h"
#include "io/exr.h"
#include "io/png_label.h"
#include "lut/sky_lut.h"

namespace skybake::fog {

// Where the depth function's parameters live (docs/fog.md, "Where a and p live").
//   kPerSlice  (a, p) per channel are fitted per depth table (sun angle), then, per slice of the fog
//              LUT, interpolated in the slice's sun zenith angle (ln a and p linear between the
//              tables' angles, constant beyond the first and the last); the evaluator blends them
//              between slices as the LUT (fog_evaluator.h);
//   kGlobal    one (a, p) per channel for every sun angle: the talk's model;
//   kPerSliceElevation  as kPerSlice, and a also per elevation node of the depth tables (v =
//              (elevation/90 deg)^(1/2)): k fitted per table and elevation, stored as
//              a = k / theta^p with the table's p, interpolated as a; the evaluator is linear in v.
enum class ParamMode { kGlobal, kPerSlice, kPerSliceElevation };
const char* ParamModeName(ParamMode m);  // "global", "per-slice", "per-slice-elevation"
std::optional<ParamMode> ParseParamMode(const std::string& name);

struct FogFitOptions {
  AngleDefinition angle = AngleDefinition::kPath;
  bool per_channel = true;            // false: one (a, p) fitted on luminance, used for R, G and B
  ParamMode params = ParamMode::kPerSliceElevation;  // docs/fog.md, "Where a and p live"
  // The depth tables (sun zenith angles, deg) the fit uses; empty: all. The errors are measured on
  // every table, so leaving tables out measures the interpolation between sun angles.
  std::vector<double> fit_sun_zenith_deg;
  // The fits use every n-th elevation row of the tables (and the last); the errors are measured
  // on all rows, so n = 2 measures the interpolation between elevation nodes.
  int fit_elevation_stride = 1;
  FitOptions fit;
  double night_end_zenith_deg = 108.0;  // lut::SkyLutDecoder's night ramp (the fog's night value is 0)
  double near_depth_m = 1000.0;         // "near the camera": depth <= this (the 1 km)
  double horizon_elevation_deg = 1.0;   // "at the horizon": elevation <= this
};

// Relative luminance error |Y_model / Y_ref - 1| over a set of samples.
struct ErrorStats {
  size_t count = 0;
  double rms = 0.0, max = 0.0;
  std::array<double, 3> channel_rms{0, 0, 0};  // |c_model / c_ref - 1|, Linear Rec.2020
  // Where the max is.
  double max_sun_zenith_deg = 0, max_elevation_deg = 0, max_azimuth_deg = 0, max_depth_m = 0, max_x = 0;
};

struct ProductStats {
  ErrorStats all, near, horizon, near_horizon, far, infinite_depth;
  std::vector<ErrorStats> near_per_sun, all_per_sun;  // per depth table
};

// The fog's fit error (luminance, "fit" as in ProductStats) of other parameter choices on the same
// render: what per-slice parameters gain over the global pair, and what an azimuth dimension would.
struct FitDiagnostic {
  std::string name, description;
  ErrorStats all, near, horizon;
};

struct FogProducts {
  std::string sky;
  FogParams params;
  FogFitOptions options;
  std::array<FitResult, 3> fit_fog, fit_shadowed;  // the global fit, per channel (luminance fit: three copies)
  // Per depth table (FogRender::tables order): used by the fit, and its own fit (per-slice mode).
  std::vector<bool> table_in_fit, elevation_in_fit;
  std::vector<std::array<FitResult, 3>> table_fit_fog, table_fit_shadowed;
  std::vector<FitDiagnostic> diagnostics;
  lut::PackedTexture fog, shadowed, attenuation;
  lut::SkyRender layout;  // the slices' mappings (for lut::SkyKtx2)
  gt7::TexelGrid texel_grid = gt7::TexelGrid::kNodes;  // the render's

  ProductStats fog_fit, fog_eval, shadowed_fit, shadowed_eval;
  // Attenuation LUT (packed, interpolated) vs the exact sunlight-weighted transmittance at the
  // depth tables' (x, elevation): absolute error per channel.
  std::array<double, 3> attenuation_rms_abs{0, 0, 0}, attenuation_max_abs{0, 0, 0};
  size_t excluded_samples = 0;   // reference luminance <= 0
  double reference_noise_rms = 0.0;  // RMS of Y_stderr / Y over the fog samples (path references)
  // Relative luminance errors per depth table, in FogRender::TableIndex order (NaN: excluded).
  std::vector<std::vector<float>> residual_fog_fit, residual_fog_eval, residual_shadowed_fit, residual_shadowed_eval;
  std::vector<std::vector<std::array<float, 3>>> residual_fog_eval_rgb;
};

// Fits, packs and measures. `files_read` receives the colour-matching table (depfile).
FogProducts BuildFogProducts(const FogRender& render, const std::string& sky, const FogFitOptions& options,
                             const ColorConfig& config, std::vector<std::filesystem::path>* files_read);

// The evaluator on the packed textures (what BuildFogProducts measures).
FogEvaluator MakeEvaluator(const FogProducts& products);

// Every file of a sky's products, encoded in memory, by name: for prefix P (e.g. "fog_clear")
//   P.json                  fitted parameters (units, provenance, the file names below)
//   P.ktx2, P_array.ktx2, P.dds                       fog LUT (3D, 2D array, DDS volume)
//   P_shadowed.ktx2, P_shadowed_array.ktx2, P_shadowed.dds
//   P_attenuation.ktx2, P_attenuation.dds             attenuation LUT (2D)
//   P.exr                   inspection (the three textures decoded, inputs, clamp flags)
//   P_report.json           residual statistics, fit status, packing
//   P_residuals.exr, P_residuals.png                  residual maps (the PNG labelled with `font`)
std::map<std::string, std::string> EncodeFogProducts(const FogRender& render, const FogProducts& products,
                                                     const std::string& prefix, const Provenance& provenance,
                                                     const Font& font);
std::vector<std::string> FogProductFiles(const std::string& prefix);

}  // namespace skybake::fog
