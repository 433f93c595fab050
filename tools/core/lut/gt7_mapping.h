// GT7's adaptive sky LUT mappings (GT7 sky talk, "Adaptive Mapping of LUT
// (time component)", "(spherical direction)", "Detail of Adaptive Mapping", "Concept Code";
// docs/lut-pack.md has the derivations and the decisions).
//
// TIME (sun zenith angle theta_z per slice; 64 slices = 48 upper + 16 lower in GT7):
//   upper region, i = 0 .. Nu-1:  d_i = lerp(d_min, d_max, (i / (Nu - 1))^p), with d_min = R - r the
//     vertical and d_max = sqrt(R^2 - r^2) the horizontal distance from the observer (radius r)
//     to the top of the atmosphere (radius R); theta_z is the zenith angle whose path to the
//     boundary has length d_i:  R^2 = r^2 + d^2 + 2 r d cos(theta)  =>
//     cos(theta_i) = ((R - r)(R + r) - d_i^2) / (2 r d_i)     (theta_0 = 0, theta_{Nu-1} = 90 deg)
//     p = 1 is the talk's mapping ("gt7"); p = 2 ("gt7-quadratic") is skybake's variant: the talk's
//     first upper step is 0 -> 35.2 deg, too wide to interpolate (docs/lut-pack.md measures 14 %
//     RMS luminance error half-way), and p = 2 brings it to 5.6 deg while the last step near the
//     horizon grows from 0.2 to 0.4 deg; it mirrors the lower region's square.
//   lower region, i = Nu .. Nu+Nl-1:  theta_z = lerp(90 deg, 100 deg, ((i - Nu) / (Nl - 1))^2).
//   The talk's two formulas both give 90 deg at their ends, so slices Nu-1 and Nu are the same
//   sun position (rendered twice; see docs/lut-pack.md "Decisions"); zenith angles are
//   non-decreasing in i and strictly increasing everywhere else.
//   Inverse (continuous slice coordinate s in [0, N-1]): upper s = (Nu-1) ((d(theta) - d_min) /
//   (d_max - d_min))^(1/p) with d(theta) = sqrt(r^2 cos^2 + (R-r)(R+r)) - r cos; lower
//   s = Nu + (Nl-1) sqrt((theta - 90)/10); s is clamped to the last slice beyond 100 deg (what
//   the decoder does below -10 deg elevation is in lut/decoder.h).
//
// SPHERE (texel (x, y) of a W x H slice at u = (x + 1/2)/W, v = (y + 1/2)/H; u covers one half of
// the azimuths - the sky is symmetric about the sun's vertical plane, so a texel is its own
// mirror). Local frame as in lut/directions.h: +z zenith, +x the sun's azimuth, the sun at
// s = (sin theta_s, 0, cos theta_s).
//   sun-aligned family (theta_s <= threshold): polar coordinates (theta, phi) around the sun with
//     the frame  t = (cos theta_s, 0, -sin theta_s)  (phi = 0: from the sun straight down towards
//     the horizon below it),  b = (0, 1, 0)  (phi = 90 deg), s = t x b;
//       direction = cos(theta) s + sin(theta) (cos(phi) t + sin(phi) b),   phi = pi u;
//     horizon normalisation: the horizon is at angle edge(phi) = pi/2 - atan(cos(phi) tan(theta_s))
//     from the sun along phi (exact for this frame: solve direction_z = 0), and
//       theta = 2 v' edge                            (v' <= 1/2: sun -> horizon)
//       theta = edge + (2 v' - 1)(pi - edge)         (v' > 1/2: horizon -> anti-sun point)
//     with v' the concept code's nonlinear transform of v (a = 0.5, b = 0.8, c = 0.25, d = 0.5,
//     p = 2): v' = c (v/a)^2 near the sun, v' = c + (d - c)(1 - k^2) with k = (v - b)/(b - a) above
//     the horizon, v' = 1 - (1 - d) sqrt(1 - k^2) with k = (v - b)/(1 - b) below it. The horizon is
//     the row v = b = 0.8 for every phi and theta_s (80 % of the rows above it), and texels
//     crowd at the sun (v = 0) and on both sides of the horizon (dv'/dv = 0 at v = b).
//   latitude-longitude family (theta_s > threshold): view zenith theta = pi v', azimuth from the
//     sun phi = pi u^2 (texels crowd towards the sun's azimuth, u = 0), with
//       K = min(1/2, theta_s / pi),  v' = sqrt(K^2 - (v - K)^2)  (v <= K),
//                                     v' = 1 - sqrt((1 - K)^2 - (v - K)^2)  (v > K)
//     so that rows crowd at the sun's zenith angle (dv'/dv = 0 at v = K), i.e. at the horizon.
//     The concept code adds pi/2 to phi for its own world frame; here phi is measured from the
//     sun's azimuth directly (docs/lut-pack.md).
//   threshold: sun elevation 15 deg (zenith 75 deg). The talk only shows the corner case at 3, 1.5
//     and 0 deg; measured on the clear sky (docs/lut-pack.md, "Threshold"), the sun-aligned
//     family's decode error between slices grows as the sun nears the horizon (edge(0) -> 0 squeezes
//     the sky below the sun; 2.1 % RMS at 8 deg, 7.4 % at 3 deg elevation) while the lat-long
//     family stays near 0.6 %, and the two cross at 12-15 deg elevation.
// Every inverse (direction -> uv) is analytic.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lut/directions.h"

namespace skybake::gt7 {

// ------------------------------------------------------------------------------------- time

// The slice counts and the upper region's exponent: what a time mapping's name says.
struct TimeMappingKind {
  int upper = 48;            // Nu (GT7: 48)
  int lower = 16;            // Nl (GT7: 16)
  double upper_power = 1.0;  // p: 1 = the talk ("gt7"), 2 = "gt7-quadratic"
  bool operator==(const TimeMappingKind&) const = default;
};

struct TimeMapping {
  double observer_radius_m = 6371e3;  // r: planet radius + observer altitude
  double top_radius_m = 6471e3;       // R: planet radius + top of the atmosphere
  int upper_slices = 48;              // Nu
  int lower_slices = 16;              // Nl
  double upper_power = 1.0;           // p
  static constexpr double kLowerEndZenithDeg = 100.0;  // the last slice: sun 10 deg below the horizon

  // Checks r < R and Nu, Nl >= 2, p > 0; UsageError otherwise.
  static TimeMapping ForPlanet(double planet_radius_m, double top_m, double observer_altitude_m,
                              const TimeMappingKind& kind = {});
  // ForPlanet with the kind of a name (ParseName); UsageError naming the accepted forms.
  static TimeMapping FromName(const std::string& name, double planet_radius_m, double top_m, double observer_altitude_m);
  int slices() const { return upper_slices + lower_slices; }
  double DMinM() const;  // vertical distance to the boundary, R - r
  double DMaxM() const;  // horizontal distance to the boundary, sqrt(R^2 - r^2)
  // Length of the path from the observer to the boundary along zenith angle theta (<= 90 deg).
  double PathToBoundaryM(double zenith_rad) const;
  double SliceZenithRad(int i) const;
  std::vector<double> SliceZenithDeg() const;
  // Continuous slice coordinate s of a sun zenith angle, in [0, slices - 1] (clamped at both ends:
  // beyond 100 deg it is the last slice). At exactly 90 deg it is Nu - 1 (= slice Nu, the same sun).
  double SliceCoordinate(double zenith_rad) const;
  // "gt7 time mapping: 48 upper slices ... r = ... m, R = ... m", for metadata and provenance.
  std::string Describe() const;
  TimeMappingKind kind() const { return {upper_slices, lower_slices, upper_power}; }
  // "gt7" (the talk: 48 + 16, p = 1) or "gt7-quadratic" (p = 2), optionally with ":<Nu>+<Nl>"
  // (e.g. "gt7:3+2" for reduced bakes); nullopt if malformed.
  static std::optional<TimeMappingKind> ParseName(const std::string& name);
};

// ------------------------------------------------------------------------------------- sphere

enum class SphereFamily { kSunAligned, kLatLong };
const char* SphereFamilyName(SphereFamily f);

inline constexpr double kDefaultThresholdElevationDeg = 15.0;

// Where the texels of a W x H slice sit in (u, v) (both grids use the same (u, v) -> direction maps):
//   kCentres  texel (x, y) at u = (x + 1/2)/W, v = (y + 1/2)/H: lut-pack's sky LUTs (the talk's
//             concept code samples texel centres);
//   kNodes    texel (x, y) at u = x/(W - 1), v = y/(H - 1), nodes at both ends (W, H >= 2): fog-fit's
//             fog LUTs (docs/fog.md, "Texel grid"). The latitude-longitude family then has a row at
//             v = 0, the zenith (with centres its first row is at view zenith 20 deg for K = 0.42 and
//             every view above it clamps to that row, whatever its azimuth), and columns on the sun's
//             vertical plane at both ends. A shader samples texel coordinates ((u (W-1) + 1/2)/W,
//             (v (H-1) + 1/2)/H), as the fog's attenuation LUT.
enum class TexelGrid { kCentres, kNodes };
const char* TexelGridName(TexelGrid g);  // "centres", "nodes"
std::optional<TexelGrid> ParseTexelGrid(const std::string& name);

// The concept code's nonlinear v transforms and their inverses (each monotonic on [0, 1]).
double SunAlignedWarp(double v);     // v -> v'
double SunAlignedUnwarp(double vp);  // v' -> v
double LatLongWarp(double v, double k);
double LatLongUnwarp(double vp, double k);
// The angle from the sun to the horizon along azimuth phi around the sun (sun-aligned frame);
// requires theta_s < 90 deg.
double HorizonEdge(double phi, double sun_zenith_rad);

struct SphereMapping {
  // Below this sun elevation (deg) the latitude-longitude family is used.
  double threshold_elevation_deg = kDefaultThresholdElevationDeg;

  double ThresholdZenithRad() const { return (90.0 - threshold_elevation_deg) * 3.14159265358979323846 / 180.0; }
  SphereFamily FamilyFor(double sun_zenith_rad) const {
    return sun_zenith_rad <= ThresholdZenithRad() ? SphereFamily::kSunAligned : SphereFamily::kLatLong;
  }
  // (u, v) in [0, 1]^2 -> unit direction, with the family of this sun zenith angle.
  std::array<double, 3> Direction(double u, double v, double sun_zenith_rad) const {
    return DirectionIn(FamilyFor(sun_zenith_rad), u, v, sun_zenith_rad);
  }
  // Unit direction -> (u, v) in [0, 1]^2 (the inverse; directions with y < 0 map to their mirror).
  std::array<double, 2> Uv(const std::array<double, 3>& d, double sun_zenith_rad) const {
    return UvIn(FamilyFor(sun_zenith_rad), d, sun_zenith_rad);
  }
  // The same with an explicit family (the decoder reads each slice with its own family). The
  // sun-aligned family needs theta_s < 90 deg (InternalError otherwise).
  static std::array<double, 3> DirectionIn(SphereFamily f, double u, double v, double sun_zenith_rad);
  static std::array<double, 2> UvIn(SphereFamily f, const std::array<double, 3>& d, double sun_zenith_rad);
  // The mapping in words, ending with where the texels of `grid` sit.
  std::string Describe(TexelGrid grid = TexelGrid::kCentres) const;
};

// The GT7 sphere mapping as a SkyMapping (sky-render --mapping gt7): W x H texels, each its own
// mirror (u covers half the azimuths), on the texel grid `grid` (kNodes needs W, H >= 2).
class Gt7SkyMapping : public SkyMapping {
 public:
  Gt7SkyMapping(int width, int height, SphereMapping sphere = {}, TexelGrid grid = TexelGrid::kCentres)
      : w_(width), h_(height), sphere_(sphere), grid_(grid) {}
  std::string Name() const override { return "gt7"; }
  int width() const override { return w_; }
  int height() const override { return h_; }
  std::optional<std::array<double, 3>> TexelDirection(int x, int y, double sun_zenith_rad) const override;
  std::array<int, 2> Mirror(int x, int y) const override { return {x, y}; }
  std::string Describe() const override;
  const SphereMapping& sphere() const { return sphere_; }
  TexelGrid grid() const { return grid_; }
  // (u, v) of texel (x, y) on this grid.
  std::array<double, 2> TexelUv(int x, int y) const;

 private:
  int w_, h_;
  SphereMapping sphere_;
  TexelGrid grid_;
};

}  // namespace skybake::gt7
