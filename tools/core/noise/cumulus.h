// The cumulus map (cumulus-map): a 2D texture of cloud density and cloud type over the world,
// with more texels near the world centre, sampled from a stationary weather field that the wind
// carries along.
//
// GT7 sky talk, "Modeling of Clouds": "2D texture (256 * 256),
// 240 km * 240 km, nonlinear texel distribution optimizations ... supplied by weather sim ...
// based on Perlin noise ... advected by the wind"; "the more central the world, the more texels".
// Frostbite's weather texture (Hillaire 2016 §5.3.1) holds
// the same two quantities: "Red: 2d projected cloud density, Green: cloud type".
//
// World frame: x east, y north, metres, origin at the world centre. Texture frame: texel (i, j),
// i along +x, j along +y (row 0 is the southern edge; KTXorientation "ru").
//
// 1. Nonlinear texel distribution, per axis (the same for x and y). With u in [-1, 1] the
//    texture coordinate about the centre (u = 2 (i + 1/2)/N - 1 at texel centres), R the half
//    size of the map and r the ratio of the texel size at the edge to that at the centre:
//      x(u) = R sinh(a u) / sinh(a),             a = arccosh(r)
//      u(x) = arcsinh(x sinh(a) / R) / a         (the exact inverse; both odd and monotone)
//      dx/du = R a cosh(a u) / sinh(a),          texel size h(u) = (2/N) dx/du
//    so h(edge)/h(centre) = cosh(a) = r, and r = 1 is the uniform map x = R u (a -> 0 limit).
//    With N = 256, R = 120 km, r = 4: h(centre) = 0.499 km, h(edge) = 1.997 km (uniform: 0.9375 km).
//    A shader finds the texel of a world point with u(x) (one asinh per axis).
//
// 2. Weather field on the unbounded plane (int64 lattice: it never repeats, so advection shows no
//    wrap). Two independent fBm of 2D gradient noise (noise/lattice.h GradientNoise2),
//      w(p) = sum_k g^k n(p L^k / lambda) / sum_k g^k,  lambda = feature size of the first octave,
//    mapped to uniform variables by their own cumulative distribution C (calibrated once per
//    parameter set on a 512 x 512 sample spanning ~316 x 316 first-octave cells, tabulated at
//    4097 quantiles, piecewise linear):  q(p) = C(w(p)) ~ U(0, 1). Then, for the requested cloud
//    cover c (area fraction with clouds) and density exponent gamma:
//      density d(p) = ((q - (1 - c)) / c)^gamma  for q > 1 - c, else 0
//      => P(d > 0) = c, and over the cloudy part d = U^gamma: mean 1/(1 + gamma);
//      type    t(p) = C_t(w_t(p)) ~ U(0, 1)  (0 = the first cloud type of the coverage texture,
//                                              1 = the last; docs/clouds.md)
// 3. Advection: the map at time t samples the stationary field at p - V t (V = wind vector, m/s),
//    i.e. the weather pattern moves with velocity V, and the map at t2 is the map at t1 shifted
//    by V (t2 - t1) in world space: a sequence of maps is consistent by construction.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/progress.h"
#include "io/yaml.h"

namespace skybake::noise {

class CumulusMapping {
 public:
  // resolution N texels per side, half_extent_m R, edge_to_centre_ratio r >= 1.
  CumulusMapping(int resolution, double half_extent_m, double edge_to_centre_ratio);
  int resolution() const { return n_; }
  double half_extent_m() const { return r_m_; }
  double a() const { return a_; }
  double WorldFromU(double u) const;   // x(u), m
  double UFromWorld(double x_m) const; // u(x)
  double DxDu(double u) const;         // m per unit u
  double TexelSizeM(double u) const { return DxDu(u) * 2.0 / n_; }
  // u at the centre of texel i, and the continuous texel coordinate (texel i spans [i, i+1)).
  double TexelCentreU(int i) const { return 2.0 * (i + 0.5) / n_ - 1.0; }
  double TexelCoord(double x_m) const { return 0.5 * (UFromWorld(x_m) + 1.0) * n_; }

 private:
  int n_;
  double r_m_;
  double a_;
  double sinh_a_;
};

struct FbmSpec {
  double feature_size_m = 40e3;  // lambda: period of the first octave's lattice cells
  int octaves = 4;
  double lacunarity = 2.0;
  double gain = 0.5;
  // The finest octave's cell size lambda / L^(octaves - 1).
  double FinestCellM() const;
};

struct WeatherSpec {
  uint64_t seed = 0;
  double coverage = 0.5;          // c: requested area fraction with clouds, [0, 1]
  double density_exponent = 1.0;  // gamma
  FbmSpec density;                // the coverage/density fBm
  FbmSpec type;                   // the cloud-type fBm
};

class WeatherField {
 public:
  explicit WeatherField(const WeatherSpec& spec);
  ~WeatherField();
  WeatherField(WeatherField&&) noexcept;
  // Raw fBm values (before the distribution transform).
  double RawDensity(double x_m, double y_m) const;
  double RawType(double x_m, double y_m) const;
  // q = C(w) in [0, 1], d and t as above.
  double DensityQuantile(double x_m, double y_m) const;
  double Density(double x_m, double y_m) const;
  double Type(double x_m, double y_m) const;
  const WeatherSpec& spec() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Valid ranges (docs/clouds.md): a wind of up to 100 m/s per component (jet-stream cores
// reach ~100 m/s) and a map time of up to 1e7 s (116 days) either side of 0, so that
// x - wind t stays within 1e9 m, where a double still resolves 2.2e-7 m.
inline constexpr double kMaxWindMS = 100.0;
inline constexpr double kMaxAbsTimeS = 1e7;

struct CumulusSpec {
  int resolution = 256;              // texels per side (GT7: 256)
  double size_m = 240e3;             // side of the square (GT7: 240 km)
  double edge_to_centre_ratio = 4.0; // r
  WeatherSpec weather;
  std::array<double, 2> wind_m_s{0.0, 0.0};  // (east, north)
  double time_s = 0.0;
  CumulusMapping Mapping() const { return CumulusMapping(resolution, 0.5 * size_m, edge_to_centre_ratio); }
};

// Loads and validates clouds/cumulus.yaml (schema in docs/clouds.md); InputError with file:line.
// Includes the anti-aliasing check: the finest density/type octave must span at least two texels
// at the map edge.
CumulusSpec LoadCumulusSpec(const std::filesystem::path& path);
CumulusSpec ParseCumulusSpec(const YamlDocument& doc);
std::string CanonicalCumulusYaml(const CumulusSpec& spec);

// Row-major N x N texels, channel-interleaved: values[(j N + i) 2 + c], c = 0 density, 1 type;
// texel (i, j) at world (x(u_i), y(u_j)) - V t.
struct CumulusMap {
  int resolution = 0;
  std::vector<float> values;
  float At(int i, int j, int c) const { return values[(static_cast<size_t>(j) * resolution + i) * 2 + c]; }
};

// TBB over rows; identical for any thread count.
CumulusMap GenerateCumulusMap(const CumulusSpec& spec, const WeatherField& field, const ProgressFn& progress = {});

}  // namespace skybake::noise
