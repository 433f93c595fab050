// Reference fog renders (sky-render fog; docs/fog.md, "Reference renders"): what fog-fit fits
// and checks, computed from an atmosphere by the path tracer (the Monte-Carlo reference) or the
// `orders` method (deterministic, all orders), both through the view-segment definition of
// transport/view_segment.h: only the medium on the view ray below the cut altitude c and closer
// than the depth scatters toward the observer, lit by the full atmosphere; no ground surface.
//
// One render holds, for one atmosphere, observer altitude and cut:
//   LUT slices      the fog of the whole segment (x = 1, to the cut sphere) and the shadowed fog
//                   (the same without the single-scattered sun: GT7's "Shadowed Fog LUT") on
//                   lut-pack's GT7 sphere mapping W x H for every slice of a GT7 time mapping;
//                   directions below the horizon are clamped to it (fog/fog_model.h);
//   depth tables    per listed sun zenith angle, the fog and shadowed fog for every
//                   (normalised depth x_j = (j/n)^3, j = 1..n) x (azimuth from the sun) x
//                   (elevation e_i = 90 deg (i/(m-1))^2, i = 0..m-1): the data of the fit;
//   transmittance   spectral, from the observer to depth x_j D along elevation e_i;
//   attenuation     spectral transmittance on the attenuation LUT's nodes (u, v) in [0,1]^2:
//                   x = u^3, elevation theta = v^2 (fog/fog_model.h);
//   sun             the extraterrestrial spectrum E_0 (for sunlight-weighted channel colours).
// Radiances are CIE-XYZ-D65 (cd/m^2) from the scene's observer, as sky-render render writes.
//
// Deterministic: work is split by output element (TBB), the path tracer draws one stream per
// (product, element); the bytes are the same at any thread count. A shard (fog/fog_shard.h:
// a contiguous range of the LUT slices and depth tables) computes its elements with the same
// bytes, and sky-render merge joins the shards into the unsharded file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "fog/fog_model.h"
#include "io/exr.h"
#include "io/progress.h"
#include "lut/gt7_mapping.h"
#include "transport/sky_method.h"
#include "transport/sky_scene.h"
#include "transport/sky_shard.h"

namespace skybake::fog {

struct FogRenderOptions {
  std::string method = "orders";  // "orders" or "path"
  SkyMethodOptions method_options;
  double cut_altitude_m = 1000.0;
  double observer_altitude_m = -1.0;  // < 0: the atmosphere's
  // LUT slices: GT7 sphere mapping W x H, GT7 time mapping name (lut/gt7_mapping.h).
  int lut_width = 32, lut_height = 32;
  std::string time_mapping = "gt7-quadratic";
  // Texel grid of the slices (lut/gt7_mapping.h): nodes (default) puts a row at the zenith of the
  // lat-long family (docs/fog.md, "Texel grid"); centres is lut-pack's grid.
  gt7::TexelGrid texel_grid = gt7::TexelGrid::kNodes;
  // Depth tables.
  std::vector<double> sun_zenith_deg = {30, 60, 80, 88, 92, 96};
  int elevations = 17;   // m
  std::vector<double> azimuth_deg = {0, 10, 30, 60, 90, 120, 150, 180};
  int depths = 32;       // n
  // Attenuation nodes.
  int attenuation_width = 64, attenuation_height = 64;
  // Render only this shard's tasks (fog/fog_shard.h); 0/1 renders everything.
  ShardSpec shard;
};

// The depth grid x_j = (j/n)^3, j = 1..n, and the elevation grid e_i = 90 (i/(m-1))^2 deg.
std::vector<double> DepthGrid(int n);
std::vector<double> ElevationGridDeg(int m);

struct FogDepthTable {
  double sun_zenith_deg = 0.0;
  // [((e * n_az + a) * n_x + j) * 3 + c], CIE-XYZ-D65 cd/m^2; stderr of Y (0 for orders).
  std::vector<float> xyz, shadowed_xyz;
  std::vector<float> y_stderr, shadowed_y_stderr;
};

struct FogRender {
  std::string path;        // when read from a file (messages)
  std::string atmosphere;  // the atmosphere's name
  std::string method;      // "orders" or "path"
  std::string method_description;
  std::string observer;    // colour-matching functions, e.g. "cie2006_2deg"
  ShardSpec shard;         // the shard rendered (0/1: the whole render; fog/fog_shard.h)
  double planet_radius_m = 0.0, top_altitude_m = 0.0, observer_altitude_m = 0.0, cut_altitude_m = 0.0;
  std::vector<double> wavelength_nm;
  std::vector<double> sun_e0;  // W m^-2 nm^-1 per wavelength (extraterrestrial)

  // LUT slices.
  int lut_width = 0, lut_height = 0;
  gt7::TimeMapping time;
  std::string time_mapping_name;
  gt7::SphereMapping sphere;
  gt7::TexelGrid texel_grid = gt7::TexelGrid::kNodes;
  std::vector<double> slice_zenith_deg;
  std::vector<std::vector<float>> slice_xyz, slice_shadowed_xyz;  // per slice W*H*3
  std::vector<std::vector<float>> slice_y_stderr;                 // per slice W*H (fog)

  // Depth tables.
  std::vector<double> depth_x, azimuth_deg, elevation_deg;
  std::vector<FogDepthTable> tables;
  std::vector<float> depth_transmittance;  // [(e * n_x + j) * n_wl + w]

  // Attenuation nodes: [(iv * W + iu) * n_wl + w], u = iu/(W-1), v = iv/(H-1).
  int attenuation_width = 0, attenuation_height = 0;
  std::vector<float> attenuation;

  FogGeometry geometry() const { return FogGeometry(planet_radius_m, observer_altitude_m, cut_altitude_m); }
  gt7::Gt7SkyMapping mapping() const { return gt7::Gt7SkyMapping(lut_width, lut_height, sphere, texel_grid); }
  size_t TableIndex(size_t e, size_t a, size_t j) const { return (e * azimuth_deg.size() + a) * depth_x.size() + j; }
};

// The part names of LUT slice k and of the depth table at a sun zenith angle (deg).
std::string FogSlicePartName(size_t k, double sun_zenith_deg);
std::string FogTablePartName(double sun_zenith_deg);

// Renders everything above. UsageError for a method without view segments, a cut below the
// observer or above the top, bad sizes.
FogRender RenderFog(const Scene& scene, const FogRenderOptions& options, const ProgressFn& progress);

// The multi-part EXR (docs/fog.md, "Reference renders"): parts fog.slice_NN.sza_DDD.DD, depth.sza_DDD.DD,
// depth_transmittance, attenuation, sun; provenance from the scene. A shard writes the parts it
// computed and its "shard" part (fog/fog_shard.h).
void WriteFogRender(const Scene& scene, const FogRenderOptions& options, const FogRender& render,
                    const std::filesystem::path& path, const std::string& tool);
// Reads and validates (InputError(path) for anything that is not a fog render, a shard included).
FogRender ReadFogRender(const std::filesystem::path& path);

}  // namespace skybake::fog
