// Rendering a sky product with the path tracer: sky radiance on a direction grid for a list of
// sun zenith angles, plus the quantities a game needs beside it (docs/sky-render.md):
//   - sky radiance XYZ (cd/m^2) per texel with the standard error of Y and the path count;
//     the sun disk itself is excluded (it is the direct-sun output);
//   - transmittance from the observer to the top of the atmosphere vs view zenith angle and
//     wavelength (deterministic quadrature, exact to ~1e-7 for the piecewise-linear profile);
//   - direct sun irradiance at the observer, E_0(lambda) T(lambda, sun zenith) on a surface
//     normal to the sun (W m^-2 nm^-1, and XYZ in lux), zero once the sun centre is below the
//     geometric horizon of the observer's ray (the planet hides it);
//   - sky ambient irradiance on a horizontal surface (hemispherical integral of the sky
//     radiance times cos, XYZ in lux) by the path tracer's cosine-weighted estimator.
// The radiance field is symmetric about the sun's vertical plane: mirrored texels (equirect
// columns x <-> W-1-x, fisheye rows y <-> H-1-y) are computed once and copied.
// Texels are independent tasks (TBB); each uses the random stream of its (slice, texel) index, so
// results are identical at any thread count, and a shard (transport/sky_shard.h: a contiguous
// range of the render's tasks) computes its texels with the bytes the whole render gives them.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "io/progress.h"
#include "lut/directions.h"
#include "transport/path_tracer.h"
#include "transport/sky_method.h"

namespace skybake {

struct SkyRenderSettings {
  std::shared_ptr<const SkyMapping> mapping;  // the texel directions (may depend on the sun)
  std::vector<double> sun_zenith_deg;
  double observer_altitude_m = 0.0;
  bool ambient = true;
  int transmittance_angles = 181;  // view zenith 0..180 deg, uniform
  // Shard shard_index of shard_count (transport/sky_shard.h): only that range of the render's
  // tasks (path: slice x mirror-pair texel; deterministic methods: slices) is computed.
  int shard_index = 0;
  int shard_count = 1;
};

struct SkySlice {
  size_t index = 0;  // in settings.sun_zenith_deg
  double sun_zenith_deg = 0.0;
  // 1 where this render computed the texel (every texel unless sharded), else 0.
  std::vector<uint8_t> owned;
  std::vector<float> xyz;       // [texel * 3 + c], cd/m^2; NaN outside the mapping
  std::vector<float> y_stderr;  // cd/m^2
  std::vector<float> paths;
  ColorEstimate ambient;                  // lux
  std::vector<double> sun_irradiance;     // W m^-2 nm^-1 per grid wavelength (normal incidence)
  std::array<double, 3> sun_xyz{0, 0, 0};  // lux, normal incidence
};

struct SkyRenderResult {
  std::vector<SkySlice> slices;  // the slices the shard touches (all, unsharded), in order
  std::vector<double> transmittance_zenith_deg;
  std::vector<double> transmittance;  // [angle * n_wl + wl]
  uint64_t total_paths = 0;
};

SkyRenderResult RenderSky(const PathTracer& tracer, const SkyRenderSettings& settings, const ProgressFn& progress);

// The same products from a deterministic method (transport/sky_method.h): standard errors and
// path counts are 0; the ambient irradiance is the method's radiance integrated over the upper
// hemisphere by a grid and a cap around the sun (transport/ambient.h).
SkyRenderResult RenderSkyDeterministic(const SkyMethod& method, const AtmosphereModel& model,
                                       const std::vector<std::array<double, 3>>& xyz_weights,
                                       const SkyRenderSettings& settings, const ProgressFn& progress);

// Transmittance (exact for the piecewise-linear profile up to the quadrature: composite
// Gauss-Legendre on 100 m of path) from a point at `altitude_m` along view zenith `zenith_rad`
// to the top of the atmosphere, for wavelength wl; 0 if the ray hits the ground.
double TransmittanceToSpace(const AtmosphereModel& model, double altitude_m, double zenith_rad, size_t wl);
// The same at every wavelength of the model (or only at `only_wl`) into out, in one walk along
// the ray; each value is the single-wavelength one, bit for bit.
inline constexpr size_t kAllWavelengths = static_cast<size_t>(-1);
void TransmittanceToSpace(const AtmosphereModel& model, double altitude_m, double zenith_rad, std::vector<double>* out,
                          size_t only_wl = kAllWavelengths);

}  // namespace skybake
