// A renderable scene: an atmosphere file + its profiles + the Mie tables of its aerosol layers,
// built into an AtmosphereModel on a wavelength grid, with the colour weights and the OCIO
// config; and the products sky-render writes from it (docs/sky-render.md, "Outputs").
//
// Used by sky-render and by the tools that render their own inputs (fog-fit, lut-pack); every
// file read is recorded for depfiles, and the resolved parameters for provenance.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atmosphere/model.h"
#include "atmosphere/spec.h"
#include "atmosphere/vertical_profiles.h"
#include "io/progress.h"
#include "spectrum/cmf.h"
#include "spectrum/grid.h"
#include "spectrum/xyz.h"
#include "transport/path_tracer.h"
#include "transport/sky_method.h"
#include "transport/sky_render.h"

namespace skybake {

struct SceneOptions {
  std::string atmosphere;
  std::string profiles;       // "" = compute from the atmosphere
  std::string mie_dir;        // folder of <particle stem>.exr
  std::string wavelengths = "360:830:5";
  std::string observer = "cie2006_2deg";
  std::string aerosol_phase = "mie";
  bool no_ozone = false;
  // Exponential air and aerosol profiles and a tent of ozone with the measured columns
  // (atmosphere/simplify.h; a simplification to measure).
  bool profiles_exponential = false;
  std::string illumination = "sun";
  double target_error = 0.01;
  uint64_t min_paths = 64;
  uint64_t max_paths = uint64_t{1} << 20;
  uint64_t seed = 1;
  int max_order = 0;
  std::string ocio_config;
};

struct Scene {
  AtmosphereSpec spec;
  VerticalProfiles profiles;
  WavelengthGrid grid = WavelengthGrid::Uniform(360, 830, 5);
  Observer observer = kDefaultObserver;
  AtmosphereModel model;
  std::shared_ptr<XyzWeights> xyz;
  std::vector<std::array<double, 3>> xyz_weights;  // per grid wavelength
  PathTracerSettings tracer;
  std::filesystem::path ocio_config;
  std::vector<std::filesystem::path> files_read;
  std::string parameters;  // resolved parameters (YAML) for provenance
};

// Parses "min:max:step" (nm), or "rgb" (the three-wavelength grid 680/550/440 nm, whose colour
// weights are transport/rgb_color.h's), into a grid; UsageError when malformed.
WavelengthGrid ParseWavelengthGrid(const std::string& text);

// Loads and validates everything; throws InputError (file:line) or UsageError.
Scene LoadScene(const SceneOptions& options, const ProgressFn& progress);

struct RenderOptions {
  std::string method = "path";
  SkyMethodOptions method_options;  // deterministic methods
  std::string mapping = "equirectangular";
  std::string size = "64x32";
  std::vector<double> sun_zenith_deg;
  // "gt7", "gt7-quadratic" (optionally ":<upper>+<lower>"): render the slices of that GT7 time
  // mapping for this atmosphere's planet and observer instead of sun_zenith_deg
  // (lut/gt7_mapping.h; lut-pack, docs/lut-pack.md).
  std::string time_mapping;
  double observer_altitude_m = -1.0;  // < 0: the atmosphere's
  // "K/N": render only shard K of N (transport/sky_shard.h); "" renders the whole sky.
  std::string shard;
  std::string preview;
  std::string display = "sRGB";
  std::string white = "auto";
  double exposure_stops = 0.0;
  // "quality_choice: {...}" (transport/auto_quality.h): the automatic choice the method's quality
  // and stride came from, a line of the provenance's parameters; "" when given by hand.
  std::string quality_choice;
};

struct RenderProducts {
  SkyRenderSettings settings;
  std::string method_description;  // deterministic methods: their resolved settings (YAML)
  SkyRenderResult sky;
};

RenderProducts RenderProductsOf(const Scene& scene, const RenderOptions& options, const ProgressFn& progress);
// The multi-part EXR (docs/sky-render.md): sky.sza_<deg> parts (R, G, B = X, Y, Z in the
// config's CIE-XYZ-D65 reference space, cd/m^2; Y_stderr; paths), transmittance, sun and
// irradiance tables.
void WriteRender(const Scene& scene, const RenderOptions& options, const RenderProducts& products,
                 const std::filesystem::path& path, const std::string& tool);
void WriteRenderPreview(const Scene& scene, const RenderOptions& options, const RenderProducts& products,
                        const std::filesystem::path& path);
// The preview options (display of the OCIO config, white 'auto' or a luminance in
// (0, 1e9] cd/m^2, exposure in [-64, 64] stops), checked before any rendering; UsageError.
void CheckPreviewOptions(const Scene& scene, const RenderOptions& options);
void CheckPreviewOptions(const std::filesystem::path& ocio_config, const RenderOptions& options);
// The preview of slices given in the CIE-XYZ-D65 reference space (what the EXR holds; NaN outside
// the mapping shows black): sky-render merge writes a merged render's preview with it, the bytes
// WriteRenderPreview writes for the unsharded render.
void WritePreviewOfReference(const std::filesystem::path& ocio_config, const RenderOptions& options, int width, int height,
                             const std::vector<std::vector<float>>& slices, const std::filesystem::path& path);

}  // namespace skybake
