// The reference evaluator of fog-fit's products: the runtime math a shader does to rebuild GT7's
// global fog for any view direction, object depth and sun angle from the packed LUTs and the
// fitted parameters (docs/fog.md, "The evaluator"; GT7 sky talk, "Fog").
//
//   mu     = the view direction's zenith cosine, clamped to [0, 1] (below the horizon: the horizon's
//            geometry, fog/fog_model.h); the LUTs are read at the direction itself (their texels
//            below the horizon hold the horizon's value)
//   x      = min(d / D(mu), 1)                       normalised depth (D: distance to the cut sphere)
//   theta  = the fit's normalised angle (params.angle: path or elevation; fog_model.h)
//   L_c    = fog LUT (GT7 sphere + time mappings, lut/decoder.h: bilinear, geometric slice blend)
//   S_c    = shadowed fog LUT (the same without the single-scattered sun)
//   F_c    = (1 - exp(-k_c x)) / (1 - exp(-k_c)),  k_c = a_c theta^p_c   (and k'_c for S)
//   a_c, p_c: per-slice parameters (the default, docs/fog.md "Where a and p live"): slice k of
//            the fog LUT has its own (a, p) per channel, blended between the two slices the LUT
//            reads with the LUT's own weight t (lut::SkyLutDecoder::SliceBlend, linear in the sun
//            angle): a = (1 - t) a_i + t a_{i+1}, p likewise; beyond the last slice the last
//            slice's. Global (the talk's model, fog-fit --params global): one (a, p) per channel.
//            Per slice and elevation (fog-fit --params per-slice-elevation): a also depends on the
//            view elevation: each slice holds a at elevation nodes v_i (v = (elevation/90 deg)^(1/2),
//            the attenuation LUT's v; the depth tables' elevations), linear in v between them
//            (clamped at the ends), then blended between slices as above; p stays per slice.
//   inscattered_c = (1 - o) L_c F_c + o S_c F'_c      o = cloud occlusion in [0, 1] (GT7: "interpolated
//                                                    with Fog LUT using the cloud occlusion")
//   T_c    = attenuation LUT, bilinear at u = x^(1/3), v = (elevation / 90 deg)^(1/2), nodes at both
//            ends: texel coordinate u (W - 1), v (H - 1) (a shader samples at (u (W-1) + 1/2) / W ...)
//   pixel  = object radiance x T + inscattered
// Colours are Linear Rec.2020 (cd/m^2 for radiance; T per channel for sunlight, [E0 T]_c/[E0]_c).
// The evaluator works in double; a float32 shader doing the same steps differs by ~1e-6 relative.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "fog/fog_model.h"
#include "lut/decoder.h"
#include "lut/ktx2.h"

namespace skybake::fog {

// What fog-fit fitted (the evaluator's parameters; the JSON file's "model" section).
struct FogParams {
  std::string basis_sky;
  AngleDefinition angle = AngleDefinition::kPath;
  double planet_radius_m = 6371e3, observer_altitude_m = 0.0, cut_altitude_m = 1000.0;
  std::array<double, 3> a{1, 1, 1}, p{0, 0, 0};                    // fog, per Linear Rec.2020 channel
  std::array<double, 3> a_shadowed{1, 1, 1}, p_shadowed{0, 0, 0};  // shadowed fog
  // Per-slice parameters, one per slice of the fog LUT (the same for the shadowed fog LUT); empty:
  // the global a, p above at every sun angle.
  struct Slice {
    std::array<double, 3> a{1, 1, 1}, p{0, 0, 0}, a_shadowed{1, 1, 1}, p_shadowed{0, 0, 0};
    // Per slice and elevation: a at the elevation nodes (empty otherwise; then a above).
    std::vector<std::array<double, 3>> a_nodes, a_shadowed_nodes;
  };
  std::vector<Slice> slices;
  std::vector<double> node_v;  // elevation nodes v_i = (elevation_i / 90 deg)^(1/2), increasing; empty: no elevation axis
  FogGeometry geometry() const { return FogGeometry(planet_radius_m, observer_altitude_m, cut_altitude_m); }
};

// The attenuation LUT: W x H texels of Linear Rec.2020 transmittance (physical), nodes at both ends.
class AttenuationLut {
 public:
  AttenuationLut() = default;
  AttenuationLut(int width, int height, std::vector<float> rgb);
  // From fog-fit's KTX2 (B10G11R11, skybake.scale). InputError(display_name) when malformed.
  static AttenuationLut FromKtx2(const ktx2::Texture& texture, const std::string& display_name);
  int width() const { return w_; }
  int height() const { return h_; }
  // Bilinear at (u, v) in [0, 1]^2 (clamped), nodes at u = i/(W-1), v = j/(H-1).
  std::array<double, 3> Sample(double u, double v) const;

 private:
  int w_ = 0, h_ = 0;
  std::vector<float> rgb_;
};

struct FogValue {
  std::array<double, 3> inscattered{0, 0, 0};    // cd/m^2, Linear Rec.2020
  std::array<double, 3> transmittance{1, 1, 1};  // per channel
  double x = 0.0, theta = 0.0;                   // the normalised depth and angle used
};

class FogEvaluator {
 public:
  FogEvaluator(FogParams params, lut::SkyLutDecoder fog, lut::SkyLutDecoder shadowed, AttenuationLut attenuation);
  // From fog-fit's parameter file (JSON) and the textures it names (relative to its folder).
  // InputError(file) for a missing or malformed file; `files_read` gets every file read.
  static FogEvaluator Load(const std::filesystem::path& params_json, std::vector<std::filesystem::path>* files_read = nullptr);

  const FogParams& params() const { return params_; }
  // Fog for unit direction d (local frame of lut/directions.h), object distance depth_m (m; > D
  // means beyond the low atmosphere: x = 1), sun zenith angle, cloud occlusion o in [0, 1].
  FogValue Evaluate(const std::array<double, 3>& d, double depth_m, double sun_zenith_rad, double occlusion = 0.0) const;
  // The depth function's parameters at this sun zenith angle and view zenith cosine mu (per-slice:
  // blended; with elevation nodes: a at mu's v; global: a, p). The result's a_nodes are empty.
  FogParams::Slice ParamsAt(double sun_zenith_rad, double mu = 1.0) const;
  // The LUT terms alone (x = 1, no depth factor): fog and shadowed fog along d.
  std::array<double, 3> LutRadiance(const std::array<double, 3>& d, double sun_zenith_rad, bool shadowed) const;

 private:
  FogParams params_;
  FogGeometry geo_;
  lut::SkyLutDecoder fog_, shadowed_;
  AttenuationLut att_;
};

// A direction below the horizon clamped to it (azimuth kept; the nadir -> towards the sun).
std::array<double, 3> ClampToHorizon(const std::array<double, 3>& d);

}  // namespace skybake::fog
