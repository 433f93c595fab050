// The reference decoder of lut-pack's sky LUTs (docs/lut-pack.md, "Decoding"): the math a shader
// does to rebuild the sky radiance for any sun zenith angle and any view direction from a packed
// GT7 LUT (GT7 sky talk, "Adaptive Mapping of LUT (spherical direction)":
// "interpolation between different LUT (time) slices is possible", "it can be decoded as a sky for
// any sun elevation").
//
//   L(d, theta) for theta <= theta_last (100 deg):
//     i = min(floor(TimeMapping::SliceCoordinate(theta)), N - 2)      (the slices around theta)
//     t = (theta - theta_i) / (theta_{i+1} - theta_i)                 (linear in the sun angle)
//     L = S_i^(1 - t) S_{i+1}^t per channel (geometric; S clamped below at 1e-6 cd/m^2), or
//     L = (1 - t) S_i + t S_{i+1} (linear, the talk's "lerp" and what a hardware-filtered 3D
//     texture does). Geometric is the default: in twilight the sky falls exponentially with the sun
//     depression and the linear blend of slices 1.3 deg apart is 13-19 % off half-way (measured
//     with multiple scattering, docs/lut-pack.md "Decoding"); elsewhere the two agree within 0.3 %.
//     The weight is linear in theta rather than in the slice coordinate (which is a square root of
//     theta in the lower region): that halves the twilight error again (2.2 % -> 1.1 % RMS at
//     sun -3.2 deg, docs/lut-pack.md). The floor (below the format's smallest normal value 6.1e-5
//     and the natural night sky 1.7e-4 cd/m^2) keeps the blend continuous when a texel is 0.
//     S_k(d, theta) = bilinear(slice k, UvIn(F_k, d, theta_k*)),  F_k = the family slice k was
//       rendered with (sun-aligned iff theta_k <= threshold), theta_k* = theta for the lat-long
//       family and min(theta, threshold) for the sun-aligned one (its domain; only the slice pair
//       that straddles the threshold ever needs the clamp).
//     Reading every slice at the *target* sun angle is what makes the sun-aligned mapping work:
//     the sun, the horizon and the texels around them stay aligned between neighbouring slices.
//   below the last slice (the talk: "linear interpolation toward a constant value (< -10 deg)"):
//     f = clamp((theta - theta_last) / (theta_end - theta_last), 0, 1),
//     L = (1 - f) S_last(d, theta_last) + f C,   C = night_rgb (uniform; E_ambient(last) / pi),
//     theta_end = 108 deg (sun 18 deg below the horizon: astronomical night) by default.
//   bilinear: texel centres at ((x + 1/2)/W, (y + 1/2)/H), clamp-to-edge in u and v (u's edges are
//     the sun's vertical plane, where the sky is mirror-symmetric, so clamping is also mirroring);
//     on the node grid (gt7::TexelGrid::kNodes, fog-fit's fog LUTs: KTX2 key skybake.texel_grid =
//     "nodes") texel (x, y) is at (x/(W-1), y/(H-1)) instead. Without the key: centres.
//   Values are divided by the texture's scale (physical units: cd/m^2 in Linear Rec.2020).
// The decoder works in double; a float32 shader doing the same steps differs by ~1e-6 relative.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "lut/gt7_mapping.h"
#include "lut/ktx2.h"

namespace skybake::lut {

enum class TimeInterpolation { kGeometric, kLinear };
const char* TimeInterpolationName(TimeInterpolation t);
inline constexpr double kGeometricFloorCdM2 = 1e-6;

class SkyLutDecoder {
 public:
  // From a KTX2 sky LUT written by lut-pack (3D texture or 2D array): B10G11R11 texels, the
  // mappings, scale and night constant from the key/value data. InputError(display_name) when a
  // key is missing or malformed.
  static SkyLutDecoder FromKtx2(const ktx2::Texture& texture, const std::string& display_name);
  // From float values already in physical units (tests): slice-major [k][y][x][c].
  SkyLutDecoder(int width, int height, gt7::TimeMapping time, gt7::SphereMapping sphere, std::vector<float> rgb,
                std::array<double, 3> night_rgb, double night_end_zenith_deg = 108.0);

  int width() const { return w_; }
  int height() const { return h_; }
  int slices() const { return time_.slices(); }
  const gt7::TimeMapping& time() const { return time_; }
  const gt7::SphereMapping& sphere() const { return sphere_; }
  const std::array<double, 3>& night_rgb() const { return night_; }
  const std::string& name() const { return name_; }
  TimeInterpolation time_interpolation() const { return interp_; }
  void set_time_interpolation(TimeInterpolation t) { interp_ = t; }
  gt7::TexelGrid texel_grid() const { return grid_; }
  void set_texel_grid(gt7::TexelGrid g);  // kNodes needs W, H >= 2

  // The slices a sun zenith angle theta <= theta_last reads and the weight of the second one: i and
  // t of the blend above (t = 0 beyond the last slice, i = N - 1 there). Data tied to the slices
  // (fog-fit's per-slice parameters) are blended with the same i and t.
  std::pair<int, double> SliceBlend(double sun_zenith_rad) const;

  // Bilinear (clamp-to-edge) value of slice k at (u, v), physical units.
  std::array<double, 3> Sample(int k, double u, double v) const;
  // Slice k read along direction d for a sun at zenith theta (its own family, see above).
  std::array<double, 3> SliceRadiance(int k, const std::array<double, 3>& d, double sun_zenith_rad) const;
  // The decoded sky radiance (Linear Rec.2020, cd/m^2) along unit direction d (local frame of
  // lut/directions.h) for a sun at zenith angle theta.
  std::array<double, 3> Radiance(const std::array<double, 3>& d, double sun_zenith_rad) const;

 private:
  SkyLutDecoder() = default;
  int w_ = 0, h_ = 0;
  gt7::TimeMapping time_;
  gt7::SphereMapping sphere_;
  std::vector<float> rgb_;
  std::array<double, 3> night_{};
  double night_end_rad_ = 0.0;
  std::string name_;
  TimeInterpolation interp_ = TimeInterpolation::kGeometric;
  gt7::TexelGrid grid_ = gt7::TexelGrid::kCentres;
};

// GT7's weather blend (gt7-sky-talk.txt, "Interpolation of Basis Skies"): sum_k w_k L_k(d, theta).
std::array<double, 3> BlendRadiance(const std::vector<std::pair<const SkyLutDecoder*, double>>& weighted,
                                    const std::array<double, 3>& d, double sun_zenith_rad);

}  // namespace skybake::lut
