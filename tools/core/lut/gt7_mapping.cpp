#include "lut/gt7_mapping.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <fmt/format.h>

#include "atmosphere/ray_sphere.h"
#include "io/error.h"
#include "io/yaml.h"

namespace skybake::gt7 {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// The concept code's constants (gt7-sky-talk.txt, "Concept Code"), p = 2 exactly.
constexpr double kA = 0.50, kB = 0.80, kC = 0.25, kD = 0.50;

double Clamp01(double x) { return std::clamp(x, 0.0, 1.0); }
}  // namespace

// ------------------------------------------------------------------------------------- time

TimeMapping TimeMapping::ForPlanet(double planet_radius_m, double top_m, double observer_altitude_m,
                                   const TimeMappingKind& kind) {
  if (!(planet_radius_m > 0.0) || !(top_m > 0.0) || !(observer_altitude_m >= 0.0) || !(observer_altitude_m < top_m)) {
    throw UsageError(fmt::format("gt7 time mapping: needs 0 <= observer altitude ({} m) < top of the atmosphere ({} m) "
                                 "and a positive planet radius ({} m)",
                                 observer_altitude_m, top_m, planet_radius_m));
  }
  if (kind.upper < 2 || kind.lower < 2 || !(kind.upper_power > 0.0)) {
    throw UsageError(fmt::format("gt7 time mapping: needs at least 2 upper and 2 lower slices and a positive exponent, "
                                 "got {} + {}, p = {}",
                                 kind.upper, kind.lower, kind.upper_power));
  }
  TimeMapping t;
  t.observer_radius_m = planet_radius_m + observer_altitude_m;
  t.top_radius_m = planet_radius_m + top_m;
  t.upper_slices = kind.upper;
  t.lower_slices = kind.lower;
  t.upper_power = kind.upper_power;
  return t;
}

TimeMapping TimeMapping::FromName(const std::string& name, double planet_radius_m, double top_m, double observer_altitude_m) {
  const std::optional<TimeMappingKind> k = ParseName(name);
  if (!k) {
    throw UsageError("time mapping: expected gt7 or gt7-quadratic, optionally with :<upper>+<lower> slices (e.g. gt7:3+2), "
                     "got '" + name + "'");
  }
  return ForPlanet(planet_radius_m, top_m, observer_altitude_m, *k);
}

double TimeMapping::DMinM() const { return top_radius_m - observer_radius_m; }

double TimeMapping::DMaxM() const {
  const double h = top_radius_m - observer_radius_m;
  return std::sqrt(h * (top_radius_m + observer_radius_m));  // sqrt(R^2 - r^2) without cancellation
}

// d(theta) = sqrt(r^2 cos^2 + R^2 - r^2) - r cos; for cos >= 0 the rationalised form
// (R^2 - r^2) / (sqrt(...) + r cos) avoids the cancellation (atmosphere/ray_sphere.h).
double TimeMapping::PathToBoundaryM(double zenith_rad) const {
  return DistanceToSphereOutStableR2Mu2(observer_radius_m, std::cos(zenith_rad), top_radius_m);
}

double TimeMapping::SliceZenithRad(int i) const {
  SKYBAKE_CHECK(i >= 0 && i < slices());
  if (i < upper_slices) {
    if (i == 0) return 0.0;
    if (i == upper_slices - 1) return kPi / 2.0;
    const double d = DMinM() + (DMaxM() - DMinM()) * std::pow(static_cast<double>(i) / (upper_slices - 1), upper_power);
    const double r = observer_radius_m, R = top_radius_m;
    const double c = ((R - r) * (R + r) - d * d) / (2.0 * r * d);
    return std::acos(std::clamp(c, -1.0, 1.0));
  }
  const double f = static_cast<double>(i - upper_slices) / (lower_slices - 1);
  return (90.0 + (kLowerEndZenithDeg - 90.0) * f * f) * kDeg;
}

std::vector<double> TimeMapping::SliceZenithDeg() const {
  std::vector<double> z;
  for (int i = 0; i < slices(); ++i) z.push_back(SliceZenithRad(i) / kDeg);
  return z;
}

double TimeMapping::SliceCoordinate(double zenith_rad) const {
  if (!(zenith_rad > 0.0)) return 0.0;
  if (zenith_rad <= kPi / 2.0) {
    const double x = std::max(0.0, (PathToBoundaryM(zenith_rad) - DMinM()) / (DMaxM() - DMinM()));
    const double s = (upper_slices - 1) * (upper_power == 1.0 ? x : std::pow(x, 1.0 / upper_power));
    return std::clamp(s, 0.0, static_cast<double>(upper_slices - 1));
  }
  const double f = std::sqrt((zenith_rad / kDeg - 90.0) / (kLowerEndZenithDeg - 90.0));
  return std::min(upper_slices + (lower_slices - 1) * f, static_cast<double>(slices() - 1));
}

std::string TimeMapping::Describe() const {
  return fmt::format(
      "gt7 time mapping (gt7-sky-talk.txt, 'Adaptive Mapping of LUT (time component)'{}): {} slices; upper region "
      "i = 0..{}: d_i = lerp(d_min, d_max, (i/{})^{}) with d_min = R - r = {} m, d_max = sqrt(R^2 - r^2) = {} m, "
      "cos(theta_i) = (R^2 - r^2 - d_i^2)/(2 r d_i); lower region i = {}..{}: theta_i = lerp(90, 100 deg, "
      "((i - {})/{})^2); observer radius r = {} m, top radius R = {} m",
      upper_power == 1.0 ? "" : "; skybake's exponent p on the upper region", slices(), upper_slices - 1, upper_slices - 1,
      FormatExact(upper_power), FormatExact(DMinM()), FormatExact(DMaxM()), upper_slices, slices() - 1, upper_slices,
      lower_slices - 1, FormatExact(observer_radius_m), FormatExact(top_radius_m));
}

std::optional<TimeMappingKind> TimeMapping::ParseName(const std::string& name) {
  TimeMappingKind k;
  std::string base = name, counts;
  if (const size_t colon = name.find(':'); colon != std::string::npos) {
    base = name.substr(0, colon);
    counts = name.substr(colon + 1);
  }
  if (base == "gt7") {
    k.upper_power = 1.0;
  } else if (base == "gt7-quadratic") {
    k.upper_power = 2.0;
  } else {
    return std::nullopt;
  }
  if (name.find(':') != std::string::npos) {
    int u = 0, l = 0;
    char tail = 0;
    if (std::sscanf(counts.c_str(), "%d+%d%c", &u, &l, &tail) != 2 || u < 2 || l < 2 || u + l > 4096 ||
        counts != fmt::format("{}+{}", u, l)) {
      return std::nullopt;
    }
    k.upper = u;
    k.lower = l;
  }
  return k;
}

// ------------------------------------------------------------------------------------- sphere

const char* SphereFamilyName(SphereFamily f) { return f == SphereFamily::kSunAligned ? "sun-aligned" : "lat-long"; }

// v' = c (v/a)^2 (v <= a); d - (d - c) k^2, k = (v - b)/(b - a) (a < v <= b); 1 - (1 - d) sqrt(1 - k^2),
// k = (v - b)/(1 - b) (v > b). The concept code's middle branch c + (d - c)(1 - k^2) is written as
// d - (d - c) k^2 (the same number, without losing k^2 next to 1).
double SunAlignedWarp(double v) {
  v = Clamp01(v);
  if (v <= kA) {
    const double k = v / kA;
    return kC * k * k;
  }
  if (v <= kB) {
    const double k = (v - kB) / (kB - kA);
    return kD - (kD - kC) * k * k;
  }
  const double k = (v - kB) / (1.0 - kB);
  return 1.0 - (1.0 - kD) * std::sqrt((1.0 - k) * (1.0 + k));
}

double SunAlignedUnwarp(double vp) {
  vp = Clamp01(vp);
  if (vp <= kC) return kA * std::sqrt(vp / kC);
  if (vp <= kD) return kB - (kB - kA) * std::sqrt((kD - vp) / (kD - kC));
  // sqrt(1 - k^2) = x = (1 - v')/(1 - d)  ->  k = sqrt((1 - x)(1 + x)), 1 - x = (v' - d)/(1 - d).
  const double k = std::sqrt((vp - kD) * ((1.0 - kD) + (1.0 - vp))) / (1.0 - kD);
  return kB + (1.0 - kB) * std::min(k, 1.0);
}

// v' = sqrt(K^2 - (v - K)^2) = sqrt(v (2K - v))  (v <= K);  1 - sqrt((1 - K)^2 - (v - K)^2) =
// 1 - sqrt((1 - v)(1 - 2K + v))  (v > K): the concept code's lower-region transform, factored.
double LatLongWarp(double v, double k) {
  v = Clamp01(v);
  if (v <= k) return std::sqrt(std::max(0.0, v * (2.0 * k - v)));
  return 1.0 - std::sqrt(std::max(0.0, (1.0 - v) * (1.0 - 2.0 * k + v)));
}

double LatLongUnwarp(double vp, double k) {
  vp = Clamp01(vp);
  if (vp <= k) return k - std::sqrt(std::max(0.0, (k - vp) * (k + vp)));
  return k + std::sqrt(std::max(0.0, (vp - k) * (2.0 - k - vp)));
}

double HorizonEdge(double phi, double sun_zenith_rad) {
  return kPi / 2.0 - std::atan(std::cos(phi) * std::tan(sun_zenith_rad));
}

namespace {

struct SunFrame {
  std::array<double, 3> s, t, b;
};
SunFrame FrameOf(double sun_zenith_rad) {
  const double ss = std::sin(sun_zenith_rad), cs = std::cos(sun_zenith_rad);
  return {{ss, 0.0, cs}, {cs, 0.0, -ss}, {0.0, 1.0, 0.0}};
}
double Dot(const std::array<double, 3>& a, const std::array<double, 3>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

double LatLongK(double sun_zenith_rad) { return std::min(0.5, sun_zenith_rad / kPi); }

}  // namespace

std::array<double, 3> SphereMapping::DirectionIn(SphereFamily f, double u, double v, double sun_zenith_rad) {
  u = Clamp01(u);
  v = Clamp01(v);
  if (f == SphereFamily::kSunAligned) {
    SKYBAKE_CHECK(sun_zenith_rad >= 0.0 && sun_zenith_rad < kPi / 2.0);
    const double phi = kPi * u;
    const double edge = HorizonEdge(phi, sun_zenith_rad);
    const double vp = SunAlignedWarp(v);
    const double theta = vp <= 0.5 ? 2.0 * vp * edge : edge + (2.0 * vp - 1.0) * (kPi - edge);
    const SunFrame fr = FrameOf(sun_zenith_rad);
    const double ct = std::cos(theta), st = std::sin(theta), cp = std::cos(phi), sp = std::sin(phi);
    std::array<double, 3> d;
    for (int i = 0; i < 3; ++i) d[i] = ct * fr.s[i] + st * (cp * fr.t[i] + sp * fr.b[i]);
    return d;
  }
  const double theta = kPi * LatLongWarp(v, LatLongK(sun_zenith_rad));
  const double phi = kPi * u * u;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

std::array<double, 2> SphereMapping::UvIn(SphereFamily f, const std::array<double, 3>& d, double sun_zenith_rad) {
  if (f == SphereFamily::kSunAligned) {
    SKYBAKE_CHECK(sun_zenith_rad >= 0.0 && sun_zenith_rad < kPi / 2.0);
    const SunFrame fr = FrameOf(sun_zenith_rad);
    const double ds = Dot(d, fr.s), dt = Dot(d, fr.t), db = std::fabs(Dot(d, fr.b));
    const double theta = std::atan2(std::hypot(dt, db), ds);
    const double phi = std::atan2(db, dt);  // [0, pi]; 0 at the sun and the anti-sun point
    const double edge = HorizonEdge(phi, sun_zenith_rad);
    const double vp = theta <= edge ? theta / (2.0 * edge) : 0.5 + (theta - edge) / (2.0 * (kPi - edge));
    return {Clamp01(phi / kPi), SunAlignedUnwarp(vp)};
  }
  const double theta = std::atan2(std::hypot(d[0], d[1]), d[2]);
  const double phi = std::atan2(std::fabs(d[1]), d[0]);
  return {Clamp01(std::sqrt(phi / kPi)), LatLongUnwarp(theta / kPi, LatLongK(sun_zenith_rad))};
}

const char* TexelGridName(TexelGrid g) { return g == TexelGrid::kNodes ? "nodes" : "centres"; }

std::optional<TexelGrid> ParseTexelGrid(const std::string& name) {
  if (name == "centres") return TexelGrid::kCentres;
  if (name == "nodes") return TexelGrid::kNodes;
  return std::nullopt;
}

std::string SphereMapping::Describe(TexelGrid grid) const {
  return fmt::format(
      "gt7 sphere mapping (gt7-sky-talk.txt, 'Concept Code'; docs/lut-pack.md): u in [0,1] covers the azimuths on "
      "one side of the sun's vertical plane (y >= 0; the other side is the mirror image). Sun zenith <= {} deg "
      "(sun elevation >= {} deg): sun-aligned, phi = pi u around the sun from the direction straight below it, "
      "theta from the sun = 2 v' edge (v' <= 1/2) or edge + (2 v' - 1)(pi - edge), edge = pi/2 - atan(cos(phi) "
      "tan(theta_s)), v' = the concept code's transform (a 0.5, b 0.8, c 0.25, d 0.5, p 2; horizon at v = 0.8). "
      "Otherwise latitude-longitude: view zenith pi v' with v' = the K-transform, K = min(1/2, theta_s/pi), azimuth "
      "from the sun pi u^2. Texel (x, y) at {}",
      FormatExact(90.0 - threshold_elevation_deg), FormatExact(threshold_elevation_deg),
      grid == TexelGrid::kNodes ? "u = x/(W - 1), v = y/(H - 1) (nodes at both ends)" : "u = (x + 1/2)/W, v = (y + 1/2)/H");
}

std::array<double, 2> Gt7SkyMapping::TexelUv(int x, int y) const {
  if (grid_ == TexelGrid::kNodes) {
    SKYBAKE_CHECK(w_ >= 2 && h_ >= 2);
    return {static_cast<double>(x) / (w_ - 1), static_cast<double>(y) / (h_ - 1)};
  }
  return {(x + 0.5) / w_, (y + 0.5) / h_};
}

std::optional<std::array<double, 3>> Gt7SkyMapping::TexelDirection(int x, int y, double sun_zenith_rad) const {
  const std::array<double, 2> uv = TexelUv(x, y);
  return sphere_.Direction(uv[0], uv[1], sun_zenith_rad);
}

std::string Gt7SkyMapping::Describe() const { return fmt::format("gt7 {}x{}: ", w_, h_) + sphere_.Describe(grid_); }

}  // namespace skybake::gt7
