// The coverage texture (cumulus-map --product coverage): per cloud type, a 256 x 128 RGBA table
// indexed by the cumulus map's density (x) and altitude (y) that turns the 2D map into a 3D
// density together with the noise volumes.
//
// GT7 sky talk, "Coverage Texture": "2D texture, resolution
// 256 * 128, hand crafted values ... fetch values according to 2D density and altitude, then
// combine with frequency components ... 4 components packed into RGBA: height modulation,
// low-frequency, mid-frequency, ambient lighting". Frostbite's cloud-type texture (Hillaire 2016
// §5.3.1) gives per cloud type a density profile over the layer height; we stack one GT7 layer per
// cloud type (a 2D-array texture), selected by the map's type channel t: layer t (L - 1).
//
// Channels of texel (d, z) of a cloud type with base b, top T(d) = T0 + (T1 - T0) d and authored
// curves h, w_L, w_M, a over the height fraction s = (z - b) / (T(d) - b):
//   R  height modulation   H = d h(s)                 (0 outside 0 <= s <= 1)
//   G  low-frequency weight  W_L = e(d) w_L(s)         (0 outside)
//   B  mid-frequency weight  W_M = e(d) w_M(s)         (0 outside)
//   A  ambient              A = a(clamp(s, 0, 1))
// with the fade-in e(d) = smoothstep(0, d_fade, d) so that d = 0 has no cloud at all. Curves are
// piecewise linear in s through the authored points. The renderer's density is then (the
// contract of docs/clouds.md, after GT7's "combine with frequency components")
//   rho / rho_max = saturate(H + W_L n_low + W_M n_mid - erosion by n_high)
// where n_low is the zero-mean low-frequency volume (so H alone sets the mean cloud amount) and
// n_mid the same volume at the mid-frequency scale.
// Sampling: column i holds d_i = i / (W - 1) and row j the altitude z_j = z_bottom + j (z_top -
// z_bottom) / (H - 1), so the table's end points are exact; a shader samples at
// u = (d (W - 1) + 1/2) / W, v = ((z - z_bottom)/(z_top - z_bottom) (H - 1) + 1/2) / H.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "io/yaml.h"

namespace skybake::noise {

// A piecewise-linear curve through (s_k, v_k), s from 0 to 1 strictly increasing.
struct Curve {
  std::vector<double> s;
  std::vector<double> v;
  double operator()(double x) const;  // x clamped to [0, 1]
};

struct CloudType {
  std::string name;
  double base_m = 1000.0;
  double top_at_zero_density_m = 1500.0;
  double top_at_full_density_m = 3000.0;
  Curve height_modulation;
  Curve low_frequency;
  Curve mid_frequency;
  Curve ambient;
};

struct CoverageSpec {
  int density_texels = 256;   // W (GT7: 256)
  int altitude_texels = 128;  // H (GT7: 128)
  double altitude_bottom_m = 500.0;
  double altitude_top_m = 8500.0;
  double noise_fade_in_density = 0.1;  // d_fade
  std::vector<CloudType> types;
  double ColumnDensity(int i) const { return density_texels == 1 ? 0.0 : static_cast<double>(i) / (density_texels - 1); }
  double RowAltitudeM(int j) const {
    return altitude_bottom_m + (altitude_texels == 1 ? 0.0 : (altitude_top_m - altitude_bottom_m) * j / (altitude_texels - 1));
  }
};

CoverageSpec LoadCoverageSpec(const std::filesystem::path& path);
CoverageSpec ParseCoverageSpec(const YamlDocument& doc);
std::string CanonicalCoverageYaml(const CoverageSpec& spec);

// The four channels (H, W_L, W_M, A) of one cloud type at density d and altitude z (above).
std::array<double, 4> CoverageAt(const CloudType& type, double fade_in_density, double density, double altitude_m);

// Layers x rows x columns x RGBA: values[((l H + j) W + i) 4 + c].
struct CoverageTexture {
  int width = 0;
  int height = 0;
  int layers = 0;
  std::vector<float> values;
  float At(int layer, int i, int j, int c) const {
    return values[((static_cast<size_t>(layer) * height + j) * width + i) * 4 + c];
  }
};

CoverageTexture BuildCoverageTexture(const CoverageSpec& spec);

}  // namespace skybake::noise
