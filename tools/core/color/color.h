// Colour conversions through OpenColorIO (docs/color.md §5-§8). Every conversion between colour
// spaces in skybake goes through a processor built here from ocio/config.ocio; no RGB matrix is
// hard-coded anywhere else.
//
// Usage (the renderer):
//   ColorConfig config = ColorConfig::Load(cli_ocio_path);           // once, before threads
//   ColorProcessor to2020 = config.Converter(XyzColorSpace(observer), ocio_names::kLinearRec2020);
//   ColorProcessor view = config.Display(ocio_names::kLinearRec2020, {.white_cd_m2 = 8000});
//   to2020.Apply(pixels);                                           // interleaved RGB floats, in place
//   WritePreviewPng("sky.png", width, height, pixels, view);
//
// Thread safety (OpenColorIO issue #1216: a Config must not be used from several threads while
// it builds processors): ColorConfig serialises every use of the OCIO Config with a mutex, and a
// ColorProcessor is immutable, so Apply may run on many threads at once. Build processors once,
// before the parallel part. Apply itself splits large buffers over TBB in fixed chunks; every
// pixel is converted independently, so results do not depend on the thread count.
//
// Precision and determinism: processors are "optimised" with OCIO's OPTIMIZATION_LOSSLESS at
// 32-bit float in and out, i.e. without OCIO's fast approximations of pow/log/exp (which
// OPTIMIZATION_DEFAULT would use). Values are float32, so conversions are exact to ~1e-7
// relative. The environment variable OCIO_OPTIMIZATION_FLAGS, if set, overrides this in OCIO.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spectrum/cmf.h"

namespace skybake {

// Names in ocio/config.ocio (color/ocio_config.h builds it).
namespace ocio_names {
// Scene-referred, linear.
inline constexpr const char* kCieXyzD65 = "CIE-XYZ-D65";          // the reference (CIE 1931 2° XYZ, absolute)
inline constexpr const char* kCie2006Xyz = "CIE 2006 2deg XYZ";   // XYZ of the CIE 2006 2° observer
inline constexpr const char* kLinearRec2020 = "Linear Rec.2020";  // the scene_linear role
inline constexpr const char* kLinearRec709 = "Linear Rec.709 (sRGB)";
inline constexpr const char* kAces2065 = "ACES2065-1";
inline constexpr const char* kRaw = "Raw";  // data
// Display colour spaces.
inline constexpr const char* kSrgbDisplaySpace = "sRGB - Display";
inline constexpr const char* kRec1886DisplaySpace = "Rec.1886 Rec.709 - Display";
inline constexpr const char* kRec2100PqDisplaySpace = "Rec.2100-PQ - Display";
// Displays and views.
inline constexpr const char* kDisplaySrgb = "sRGB";
inline constexpr const char* kDisplayRec1886 = "Rec.1886 Rec.709";
inline constexpr const char* kDisplayRec2100Pq = "Rec.2100-PQ";
inline constexpr const char* kViewUntonemapped = "Un-tone-mapped";
inline constexpr const char* kViewRaw = "Raw";
}  // namespace ocio_names

// The config colour space holding XYZ computed by XyzWeights for `observer`:
// CIE-XYZ-D65 (the reference itself) for CIE 1931 2°, "CIE 2006 2deg XYZ" for CIE 2006 2°.
const char* XyzColorSpace(Observer observer);

// A display view with an exposure. The scene-linear colour c (in the processor's source space,
// absolute: Y in cd/m² for the renderer's output) is multiplied by
//     k = 2^exposure_stops / white_cd_m2
// before the view; the view maps display-linear 1.0 to the display's reference white: code value
// 1.0 (255) on sRGB and Rec.1886, and 100 cd/m² on Rec.2100-PQ (OCIO's PQ convention). So
// white_cd_m2 is the scene luminance shown as white on SDR displays; on the PQ display,
// white_cd_m2 = 100 with 0 stops reproduces absolute luminance (clipping at 10000 cd/m²).
// A clear daytime sky has luminances of order 10³-10⁴ cd/m², so white_cd_m2 ≈ 10000 previews it
// without clipping anything but the sun's neighbourhood (the view is not tone-mapped).
struct DisplayView {
  std::string display = ocio_names::kDisplaySrgb;
  std::string view = ocio_names::kViewUntonemapped;
  double white_cd_m2 = 1.0;
  double exposure_stops = 0.0;

  double Scale() const;  // k above
};

// An immutable, thread-safe colour conversion of interleaved float RGB (or XYZ in R, G, B).
class ColorProcessor {
 public:
  ColorProcessor() = default;  // empty: Apply throws InternalError
  // In place; rgb.size() must be a multiple of 3.
  void Apply(std::span<float> rgb) const;
  std::array<float, 3> Apply(std::array<float, 3> rgb) const;
  // "src -> dst" or "src -> display/view (scale k)", for messages and provenance.
  const std::string& description() const;
  // OCIO's cache id of the processor (a hash of the transforms), for provenance.
  const std::string& cache_id() const;

 private:
  friend class ColorConfig;
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

class ColorConfig {
 public:
  // Where the config is: `explicit_path` when not empty (a tool's --ocio-config), else the
  // environment variable SKYBAKE_OCIO when set and not empty, else ocio/config.ocio of the
  // repository found by FindRepoFile (io/repo_paths.h: upwards from the executable, then from the
  // working folder). $OCIO is deliberately ignored: a studio config lacks skybake's names.
  // Throws InputError when the chosen file does not exist.
  static std::filesystem::path ResolvePath(const std::filesystem::path& explicit_path = {});
  // ResolvePath + parse + OCIO validate; InputError(path) with OCIO's message on failure.
  static ColorConfig Load(const std::filesystem::path& explicit_path = {});

  const std::filesystem::path& path() const;
  // OCIO's cache id of the config, for provenance.
  std::string cache_id() const;
  std::vector<std::string> ColorSpaces() const;
  std::vector<std::string> Displays() const;
  std::vector<std::string> Views(const std::string& display) const;

  // src -> dst between colour spaces of the config. Unknown names: InputError(config path)
  // listing the known ones.
  ColorProcessor Converter(std::string_view src, std::string_view dst) const;
  // src (a scene-referred, non-data space) -> display/view, after the exposure scale k. The
  // output is display-encoded (0-1 code values). k is applied by Apply in double before the OCIO
  // processor (a uniform scale, not a colour conversion): OCIO 2.1.2's matrix composition loses
  // scales below ~1e-7, which absolute skies need (color.cpp).
  ColorProcessor Display(std::string_view src, const DisplayView& view) const;
  // The same display view (without the exposure scale) as OCIO's GPU shader: GLSL ES 3.00 text
  // of `vec4 function_name(in vec4 inPixel)` from OCIO's GpuShaderDesc, so that a shader
  // displays the textures exactly as the PNG previews do (viewer/, docs/runtime.md). A view
  // that needs uniforms or LUT textures is an InputError (skybake's config has none: its views
  // are matrices and analytic curves).
  std::string DisplayShaderGlslEs3(std::string_view src, const DisplayView& view, const std::string& function_name) const;

 private:
  ColorConfig() = default;  // only through Load: a ColorConfig always holds a valid config
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// 8-bit code values of display-encoded floats: round(clamp(v, 0, 1) · 255), half away from zero;
// NaN -> 0. Deterministic.
std::vector<uint8_t> QuantizeDisplay8(std::span<const float> display_rgb);
// rgb (interleaved, width·height·3 floats, rows top to bottom, in the display processor's source
// space) -> display view -> 8-bit RGB (the input is not modified).
std::vector<uint8_t> EncodePreview8(int width, int height, std::span<const float> rgb, const ColorProcessor& display);
// EncodePreview8 written with io/png.h WritePng8 (deterministic bytes; untouched when equal).
// Returns true when the file changed.
bool WritePreviewPng(const std::filesystem::path& path, int width, int height, std::span<const float> rgb,
                     const ColorProcessor& display);

}  // namespace skybake
