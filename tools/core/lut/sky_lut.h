// lut-pack's core (docs/lut-pack.md): sky-render products on the GT7 mappings -> the runtime
// textures GT7 ships (GT7 sky talk, "Run-time Sky Rendering Method",
// "Memory Budget of Look-up Table", "Other Look-up Tables"):
//
//   sky LUT per basis sky   W x H x N texels (N sun-elevation slices of the GT7 time mapping, the
//                           GT7 sphere mapping in each), R11G11B10F, as a KTX2 3D texture, a KTX2
//                           2D array and a DDS volume;
//   transmittance           one row per basis sky: the sunlight-weighted transmittance from the
//                           observer to space vs view zenith 0..180 deg (1 deg steps);
//   sun                     one row per basis sky: direct sun illuminance at normal incidence at
//                           the N slice sun angles (the sky LUT's time coordinate);
//   ambient                 one row per basis sky: sky illuminance on a horizontal surface at the N
//                           slice sun angles.
//
// Colour: the renders' CIE-XYZ-D65 (cd/m^2, lux) is converted to Linear Rec.2020 by OCIO
// (color/color.h), multiplied by the texture's scale (stored in the key/value data as
// skybake.scale) and packed with our R11G11B10F packer (lut/r11g11b10.h). Negative components
// (colours outside Rec.2020) and values above the format's largest finite value are clamped and
// counted; the packing error of every texel is measured in luminance (Y from OCIO's Rec.2020 ->
// XYZ) and per channel.
//
// Everything here is deterministic: texels are independent, statistics are computed serially in
// texel order, so the bytes do not depend on the thread count.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "color/color.h"
#include "lut/gt7_mapping.h"
#include "lut/ktx2.h"

namespace skybake::lut {

// A sky-render EXR rendered with --mapping gt7 --time-mapping gt7[...] (docs/sky-render.md).
struct SkyRender {
  std::string path;  // as given (messages, provenance)
  int width = 0, height = 0;
  gt7::TimeMapping time;
  std::string time_mapping_name;  // "gt7" or "gt7:U+L"
  gt7::SphereMapping sphere;
  std::vector<double> slice_zenith_deg;
  std::vector<std::vector<float>> slice_xyz;  // per slice: W*H*3, CIE-XYZ-D65 (cd/m^2), rows top to bottom
  std::string observer;                       // e.g. "cie2006_2deg"
  std::string method;                         // the render's method line ("method: orders ...")
  // The render's automatic quality choice (transport/auto_quality.h), the YAML flow mapping of its
  // "quality_choice: {...}" provenance line; "" for a render whose quality was given by hand.
  std::string quality_choice;
  std::vector<double> wavelength_nm;
  std::vector<double> transmittance_zenith_deg;
  std::vector<float> transmittance;             // [angle * n_wl + wl]
  std::vector<float> sun_irradiance;            // [slice * n_wl + wl], W m^-2 nm^-1, normal incidence
  std::vector<std::array<float, 3>> sun_xyz;      // per slice, lux (CIE-XYZ-D65), normal incidence
  std::vector<std::array<float, 3>> ambient_xyz;  // per slice, lux (CIE-XYZ-D65), horizontal surface
};

// Reads and validates; InputError(path) for anything that is not a GT7 render (wrong mapping,
// missing time mapping attributes, slice angles that disagree with the time mapping, NaNs, ...).
SkyRender ReadSkyRender(const std::filesystem::path& path);

// Statistics of packing one texture (docs/lut-pack.md, "Packing error").
struct PackStats {
  size_t texels = 0;
  // Clamping.
  size_t clamped_high = 0;           // texels with a component above the largest finite value
  double max_value = 0.0;            // largest component before clamping (stored units)
  size_t negative_texels = 0;        // texels with a negative Rec.2020 component (out of gamut)
  double worst_negative_fraction = 0.0;  // max over those of -min(component) / Y
  size_t denormal_texels = 0;        // texels with a non-zero component below 2^-14 (less precise)
  size_t zero_luminance = 0;         // texels with Y <= 0 (no relative error)
  // Relative luminance error |Y_packed - Y| / Y over the texels that were neither clamped nor
  // denormal (the in-range set, `measured`), and per channel |c_packed - c| / c.
  size_t measured = 0;
  double y_rel_rms = 0.0, y_rel_max = 0.0;
  std::array<double, 5> y_rel_percentiles{};  // 50, 90, 99, 99.9, 100 %
  std::array<double, 3> channel_rel_max{};    // R, G, B
  std::array<size_t, 6> y_rel_histogram{};    // [0,0.1) [0.1,0.2) [0.2,0.4) [0.4,0.6) [0.6,1) [1,inf) %
  size_t worst_texel = 0;                      // index of y_rel_max
};

// A packed texture: R11G11B10F texel words (little-endian bytes), the float values before
// packing and the decoded values, both in physical units (stored / scale).
struct PackedTexture {
  int width = 0, height = 0, depth = 1;  // depth: slices (sky) or 1
  double scale = 1.0;                     // stored = physical x scale
  std::string bytes;                      // 4 bytes per texel
  std::vector<float> input_rgb;           // physical, Linear Rec.2020, before clamping
  std::vector<float> decoded_rgb;         // physical, what a shader reads (/ scale)
  std::vector<uint8_t> clamp_flags;       // per texel: 1 = above max, 2 = negative component, 4 = denormal
  PackStats stats;
};

// Rec.2020 values (physical units) x scale -> R11G11B10F with statistics. `to_xyz` converts
// Linear Rec.2020 -> CIE-XYZ-D65 (for luminance). Deterministic.
PackedTexture PackRgb(int width, int height, int depth, const std::vector<float>& rgb_physical, double scale,
                      const ColorProcessor& to_xyz);

// The largest power of two 2^-k (k >= 0) such that every value x 2^-k stays at or below the
// 10-bit channel's largest finite value 64512 (so no channel clamps): the automatic scale of the
// sun, ambient and transmittance LUTs.
double AutomaticScale(const std::vector<float>& rgb_physical);

// What lut-pack builds from a set of renders.
struct LutSetOptions {
  // Stored sky value = cd/m^2 x scale (docs/lut-pack.md, "Scale"): a fixed scale, or (0) per
  // texture the largest 2^-k, k >= 0, with which no texel clamps (AutomaticScale).
  double sky_scale = 0.0;
  double night_end_zenith_deg = 108.0;  // below -10 deg the sky fades to its night constant by here
};

struct SkyLutProduct {
  std::string name;
  const SkyRender* render = nullptr;
  PackedTexture sky;
  std::array<double, 3> night_rgb{};  // cd/m^2 Rec.2020: ambient(last slice) / pi
};

struct LutSet {
  std::vector<SkyLutProduct> skies;
  PackedTexture transmittance;  // 181 x skies
  PackedTexture sun;            // slices x skies
  PackedTexture ambient;        // slices x skies
  std::vector<double> transmittance_zenith_deg;
  LutSetOptions options;
};

// Converts and packs. All renders must share the time mapping (one slice coordinate for the whole
// set); InputError(path) otherwise. `config` is the OCIO config; `cmf_paths_read` receives the
// colour-matching table used for the transmittance colours (depfile).
LutSet BuildLutSet(const std::vector<std::pair<std::string, const SkyRender*>>& renders, const LutSetOptions& options,
                   const ColorConfig& config, std::vector<std::filesystem::path>* files_read);

// The KTX2 textures (key/value data: mapping, time mapping, scale, night constant, sampling rule,
// provenance) and DDS files of a set, encoded in memory.
ktx2::Texture SkyKtx2(const LutSet& set, const SkyLutProduct& sky, bool array, const Provenance& provenance);
ktx2::Texture TableKtx2(const LutSet& set, const PackedTexture& t, const std::string& quantity,
                        const std::string& axis_u, const Provenance& provenance);

}  // namespace skybake::lut
