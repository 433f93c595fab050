// The reference fog of one basis sky as fog-fit's phases read it (docs/fog.md, "The fit"): the
// depth tables converted to Linear Rec.2020 once, per elevation the zenith cosine, the depth
// function's angle theta and the boundary distance D, and the fit of GT7's depth function on any
// subset of the samples. Shared by the parameter fit (fog_parameters.cpp), the error measurement
// (fog_errors.cpp) and the packing (fog_luts.cpp).
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "color/color.h"
#include "fog/fog_fit.h"
#include "fog/fog_luts.h"
#include "fog/fog_render.h"
#include "spectrum/xyz.h"

namespace skybake::fog {

struct FogReference {
  const FogRender* render = nullptr;
  const FogFitOptions* options = nullptr;
  std::array<double, 3> y_row{0, 0, 0};  // Linear Rec.2020 -> Y
  // Per depth table: the fog and the shadowed fog in Linear Rec.2020, FogRender::TableIndex order x 3.
  std::vector<std::vector<float>> fog, shadowed;
  std::vector<double> mu, theta, depth_max;  // per elevation: cos(zenith), the fit's theta, D (m)
  size_t ne = 0, na = 0, nx = 0, n_tab = 0;  // elevations, azimuths, depths, depth tables

  const std::vector<std::vector<float>>& Product(int shadowed_product) const { return shadowed_product ? shadowed : fog; }
};

// `to2020`: CIE-XYZ-D65 -> Linear Rec.2020; `y_row`: LuminanceRow of the inverse.
FogReference MakeFogReference(const FogRender& render, const FogFitOptions& options, const ColorProcessor& to2020,
                              const std::array<double, 3>& y_row);

// Linear Rec.2020 -> Y (the OCIO transform is linear between these linear spaces).
std::array<double, 3> LuminanceRow(const ColorProcessor& to_xyz);
double Dot(const std::array<double, 3>& a, const std::array<double, 3>& b);
// The unit view direction at an elevation and an azimuth from the sun (degrees): +z zenith.
std::array<double, 3> DirOf(double elevation_deg, double azimuth_deg);

// Which samples a fit uses: (depth table, azimuth, elevation) -> used.
using SampleFilter = std::function<bool(size_t table, size_t azimuth, size_t elevation)>;

// Fits (a, p) per channel (or once on luminance, copied to R, G, B) on the samples `use` selects:
// every depth x < 1 of each selected (table, azimuth, elevation), the target the fog at x over the
// fog at x = 1 of the same direction and sun (one elevation: p = 0, k = a).
std::array<FitResult, 3> FitOn(const FogReference& ref, const std::vector<std::vector<float>>& data, const SampleFilter& use);

// Sunlight-weighted channel transmittance [E0 T]_c / [E0]_c in Linear Rec.2020 (as lut-pack's
// transmittance LUT; lut/sky_lut.cpp BuildLutSet), from the render's sun spectrum and a spectral
// transmittance at its wavelengths. InputError (at the render's file) for an unknown observer or
// a sun colour with a non-positive Rec.2020 channel.
class SunlightTransmittance {
 public:
  SunlightTransmittance(const FogRender& render, const ColorConfig& config, std::vector<std::filesystem::path>* files_read);
  std::array<float, 3> operator()(const float* transmittance) const;
  size_t wavelengths() const { return nw_; }

 private:
  std::array<float, 3> SunRgb(const float* transmittance) const;
  const FogRender& render_;
  size_t nw_;
  std::optional<XyzWeights> weights_;
  ColorProcessor to2020_;
  std::array<float, 3> e0_rgb_{};
};

}  // namespace skybake::fog
