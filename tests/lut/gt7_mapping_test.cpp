// GT7 adaptive LUT mappings (lut/gt7_mapping.h): the time mapping's slices against an
// independent ray-sphere intersection and its inverse, and the sphere mapping's geometry (sun at
// v = 0, horizon at v = 0.8 for every azimuth, lat-long rows crowding at the sun's zenith angle),
// its analytic inverse (uv -> direction -> uv within 1e-5 texel everywhere, including next to the
// threshold elevation, the horizon row and the K row) and continuity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "io/error.h"
#include "lut/directions.h"
#include "lut/gt7_mapping.h"
#include "support/log.h"

using namespace skybake;
using namespace skybake::gt7;

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
// The largest slice of the LUTs (sunny: 32 x 128): errors are measured in its texels.
constexpr int kW = 32, kH = 128;

// Earth as in atmospheres/clear.yaml: 6371 km radius, 100 km atmosphere, observer on the ground.
TimeMapping Earth() { return TimeMapping::ForPlanet(6371e3, 100e3, 0.0); }

// Path length from (0, 0, r) along zenith angle theta to the sphere of radius R, by the quadratic
// |x + t v|^2 = R^2 solved in long double (independent of the code's rationalised form).
double PathByQuadratic(double r, double R, double theta) {
  const long double c = std::cos(static_cast<long double>(theta));
  const long double b = r * c, k = static_cast<long double>(r) * r - static_cast<long double>(R) * R;
  return static_cast<double>(-b + std::sqrt(b * b - k));
}

double Angle(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
  return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

const std::vector<double>& SunZenithsDeg() {
  static const std::vector<double> z = {0.0,  1e-7, 10.0, 35.2, 45.0, 60.0, 74.5, 75.0 - 1e-9, 75.0, 75.0 + 1e-9,
                                        80.0, 87.0, 89.9, 90.0, 90.1, 95.0, 99.9, 100.0};
  return z;
}

}  // namespace

// ------------------------------------------------------------------------------------- time

TEST(Gt7Time, SlicesFollowTheTalksTwoRegions) {
  const TimeMapping t = Earth();
  ASSERT_EQ(t.slices(), 64);
  EXPECT_NEAR(t.DMinM(), 100e3, 1e-6);
  EXPECT_NEAR(t.DMaxM(), std::sqrt(6471e3 * 6471e3 - 6371e3 * 6371e3), 1e-6);  // 1133.22 km
  const std::vector<double> z = t.SliceZenithDeg();
  EXPECT_EQ(z[0], 0.0);
  EXPECT_EQ(z[47], 90.0);
  EXPECT_EQ(z[48], 90.0);  // both regions start/end at 90 deg (docs/lut-pack.md, "Decisions")
  EXPECT_NEAR(z[63], 100.0, 1e-12);
  // Upper region: the path to the boundary of slice i is lerp(d_min, d_max, i/47).
  for (int i = 0; i < 48; ++i) {
    const double d = t.DMinM() + (t.DMaxM() - t.DMinM()) * i / 47.0;
    EXPECT_NEAR(PathByQuadratic(t.observer_radius_m, t.top_radius_m, z[i] * kDeg), d, 1e-6 * d) << i;
  }
  // Lower region: lerp(90, 100, ((i - 48)/15)^2).
  for (int i = 48; i < 64; ++i) EXPECT_NEAR(z[i], 90.0 + 10.0 * std::pow((i - 48) / 15.0, 2), 1e-12) << i;
  // Monotonic in sun elevation: zenith angles strictly increase except the shared 90 deg pair.
  for (int i = 1; i < 64; ++i) {
    if (i == 48) continue;
    EXPECT_GT(z[i], z[i - 1]) << i;
  }
  // More slices near the horizon: the steps shrink towards 90 deg in the upper region.
  for (int i = 2; i < 48; ++i) EXPECT_LT(z[i] - z[i - 1], z[i - 1] - z[i - 2] + 1e-12) << i;
  SKYBAKE_LOG("gt7 slices (deg):");
  for (int i = 0; i < 64; ++i) SKYBAKE_LOG("%s%.4f", i % 8 ? " " : "\n  ", z[i]);
  SKYBAKE_LOG("\n");
}

TEST(Gt7Time, SliceCoordinateIsTheInverse) {
  const TimeMapping t = Earth();
  for (int i = 0; i < t.slices(); ++i) {
    const double expect = i == 48 ? 47.0 : i;  // 90 deg is both slice 47 and slice 48 (same sun)
    EXPECT_NEAR(t.SliceCoordinate(t.SliceZenithRad(i)), expect, 1e-9) << i;
  }
  // Continuous and increasing between slices; clamped outside [0, 100] deg.
  double prev = -1.0;
  for (double zd = 0.0; zd <= 100.0; zd += 0.01) {
    const double s = t.SliceCoordinate(zd * kDeg);
    EXPECT_GE(s, prev) << zd;
    if (zd > 0.0 && std::fabs(zd - 90.0) > 0.02) {
      EXPECT_LT(s - prev, 1.0) << zd;  // no jumps
    }
    prev = s;
  }
  EXPECT_EQ(t.SliceCoordinate(-0.1), 0.0);
  EXPECT_EQ(t.SliceCoordinate(120.0 * kDeg), 63.0);
  // At 90 deg the coordinate jumps from 47 to 48: the same sun, so the decoded sky is continuous.
  EXPECT_NEAR(t.SliceCoordinate(90.0 * kDeg), 47.0, 1e-12);
  EXPECT_NEAR(t.SliceCoordinate(90.0 * kDeg + 1e-12), 48.0, 1e-4);
}

TEST(Gt7Time, ReducedMappingsAndNames) {
  EXPECT_EQ(TimeMapping::ParseName("gt7"), (TimeMappingKind{48, 16, 1.0}));
  EXPECT_EQ(TimeMapping::ParseName("gt7-quadratic"), (TimeMappingKind{48, 16, 2.0}));
  EXPECT_EQ(TimeMapping::ParseName("gt7:3+2"), (TimeMappingKind{3, 2, 1.0}));
  EXPECT_EQ(TimeMapping::ParseName("gt7-quadratic:4+3"), (TimeMappingKind{4, 3, 2.0}));
  EXPECT_FALSE(TimeMapping::ParseName("gt7:1+2"));
  EXPECT_FALSE(TimeMapping::ParseName("gt7:3+2x"));
  EXPECT_FALSE(TimeMapping::ParseName("gt7:03+2"));
  EXPECT_FALSE(TimeMapping::ParseName("gt7:"));
  EXPECT_FALSE(TimeMapping::ParseName("gt8"));
  const TimeMapping t = TimeMapping::ForPlanet(6371e3, 100e3, 0.0, {3, 2, 1.0});
  const std::vector<double> z = t.SliceZenithDeg();
  ASSERT_EQ(z.size(), 5u);
  EXPECT_EQ(z[0], 0.0);
  EXPECT_EQ(z[2], 90.0);
  EXPECT_EQ(z[3], 90.0);
  EXPECT_NEAR(z[4], 100.0, 1e-12);
  EXPECT_THROW(TimeMapping::ForPlanet(6371e3, 100e3, 100e3), skybake::UsageError);
  EXPECT_THROW(TimeMapping::ForPlanet(6371e3, 100e3, 0.0, {1, 16, 1.0}), skybake::UsageError);
  EXPECT_THROW(TimeMapping::FromName("gt9", 6371e3, 100e3, 0.0), skybake::UsageError);
  // A raised observer sees a shorter vertical path: d_min = top - altitude.
  EXPECT_NEAR(TimeMapping::ForPlanet(6371e3, 100e3, 2000.0).DMinM(), 98e3, 1e-6);
}

TEST(Gt7Time, QuadraticVariantSpendsSlicesOnHighSun) {
  // skybake's variant: d_i = lerp(d_min, d_max, (i/47)^2); the same ends, the same lower region,
  // the inverse still exact, the first step 5.6 deg instead of 35.2 deg.
  const TimeMapping t = TimeMapping::FromName("gt7-quadratic", 6371e3, 100e3, 0.0);
  const TimeMapping talk = Earth();
  const std::vector<double> z = t.SliceZenithDeg(), zt = talk.SliceZenithDeg();
  EXPECT_EQ(z[0], 0.0);
  EXPECT_EQ(z[47], 90.0);
  for (int i = 48; i < 64; ++i) EXPECT_EQ(z[i], zt[i]);
  for (int i = 0; i < 48; ++i) {
    const double d = t.DMinM() + (t.DMaxM() - t.DMinM()) * std::pow(i / 47.0, 2);
    EXPECT_NEAR(PathByQuadratic(t.observer_radius_m, t.top_radius_m, z[i] * kDeg), d, 1e-6 * d) << i;
    EXPECT_NEAR(t.SliceCoordinate(z[i] * kDeg), i, 1e-9) << i;
    if (i > 0) {
      EXPECT_GT(z[i], z[i - 1]);
    }
  }
  EXPECT_NEAR(z[1], 5.6, 0.1);
  EXPECT_NEAR(zt[1], 35.25, 0.01);
  EXPECT_LT(z[47] - z[46], 0.5);  // still dense at the horizon (0.2 deg for the talk's)
  SKYBAKE_LOG("gt7-quadratic slices (deg):");
  for (int i = 0; i < 64; ++i) SKYBAKE_LOG("%s%.4f", i % 8 ? " " : "\n  ", z[i]);
  SKYBAKE_LOG("\n");
}

// ------------------------------------------------------------------------------------- sphere

TEST(Gt7Sphere, WarpsAreMonotonicWithTheirInverses) {
  // The concept code's transform: 0 -> 0, a -> c, b -> d (the horizon), 1 -> 1.
  EXPECT_EQ(SunAlignedWarp(0.0), 0.0);
  EXPECT_DOUBLE_EQ(SunAlignedWarp(0.5), 0.25);
  EXPECT_DOUBLE_EQ(SunAlignedWarp(0.8), 0.5);
  EXPECT_DOUBLE_EQ(SunAlignedWarp(1.0), 1.0);
  for (double k : {87.0 / 180.0, 0.49, 0.5}) {
    EXPECT_EQ(LatLongWarp(0.0, k), 0.0);
    EXPECT_NEAR(LatLongWarp(k, k), k, 1e-15);
    EXPECT_DOUBLE_EQ(LatLongWarp(1.0, k), 1.0);
  }
  double prev_s = -1.0, prev_l = -1.0;
  for (int i = 0; i <= 100000; ++i) {
    const double v = i / 100000.0;
    const double s = SunAlignedWarp(v), l = LatLongWarp(v, 87.0 / 180.0);
    EXPECT_GE(s, prev_s) << v;
    EXPECT_GE(l, prev_l) << v;
    prev_s = s;
    prev_l = l;
    EXPECT_NEAR(SunAlignedUnwarp(s), v, 1e-7) << v;
    EXPECT_NEAR(LatLongUnwarp(l, 87.0 / 180.0), v, 1e-7) << v;
  }
  // The concept code verbatim (pow(sqrt(1 - k^2), p) with p = 2) against our factored forms.
  auto concept_code = [](double v) {
    const double a = 0.5, b = 0.8, c = 0.25, d = 0.5, p = 2.0;
    if (v <= a) {
      const double k = v / a;
      return c - c * std::pow(std::sqrt(1 - k * k), p);
    }
    if (v <= b) {
      const double k = (v - b) / (b - a);
      return c + (d - c) * std::pow(std::sqrt(1 - k * k), p);
    }
    const double k = (v - b) / (1 - b);
    return 1 - (1 - d) * std::sqrt(1 - k * k);
  };
  auto concept_lower = [](double v, double K) {
    if (v <= K) return std::sqrt(K * K - (v - K) * (v - K));
    return 1 - std::sqrt((1 - K) * (1 - K) - (v - K) * (v - K));
  };
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    EXPECT_NEAR(SunAlignedWarp(v), concept_code(v), 1e-14) << v;
    EXPECT_NEAR(LatLongWarp(v, 0.49), concept_lower(v, 0.49), 1e-7) << v;
  }
}

TEST(Gt7Sphere, SunAlignedGeometry) {
  // The sun-aligned family at any sun zenith angle below 90 deg (also above the threshold: the
  // decoder reads the slice that straddles it with this family).
  auto SA = [](double u, double v, double ts) { return SphereMapping::DirectionIn(SphereFamily::kSunAligned, u, v, ts); };
    for (double zd : {0.0, 20.0, 60.0, 75.0, 85.0, 87.0}) {
    const double ts = zd * kDeg;
    const std::array<double, 3> sun = {std::sin(ts), 0.0, std::cos(ts)};
    for (double u : {0.0, 0.1, 0.5, 0.77, 1.0}) {
      // v = 0 is the sun, v = 1 the anti-sun point, v = 0.8 the horizon for every azimuth.
      EXPECT_LT(Angle(SA(u, 0.0, ts), sun), 1e-12);
      EXPECT_NEAR(Angle(SA(u, 1.0, ts), sun), kPi, 1e-7);
      EXPECT_NEAR(SA(u, 0.8, ts)[2], 0.0, 1e-12) << zd << " " << u;
      EXPECT_GT(SA(u, 0.8 - 1e-6, ts)[2], 0.0);
      EXPECT_LT(SA(u, 0.8 + 1e-6, ts)[2], 0.0);
      // u covers the half-space y >= 0.
      EXPECT_GE(SA(u, 0.4, ts)[1], -1e-15);
    }
    // u = 0 looks from the sun straight down: the sun's vertical plane, towards the sun's azimuth.
    const std::array<double, 3> below = SA(0.0, 0.7, ts);
    EXPECT_NEAR(below[1], 0.0, 1e-15);
    EXPECT_GT(below[0], 0.0);
    // u = 1 goes from the sun over the zenith: edge = 90 deg + theta_s.
    EXPECT_NEAR(HorizonEdge(kPi, ts), kPi / 2 + ts, 1e-12);
    EXPECT_NEAR(HorizonEdge(0.0, ts), kPi / 2 - ts, 1e-12);
  }
}

TEST(Gt7Sphere, LatLongGeometry) {
  const SphereMapping m;
  for (double zd : {75.5, 87.5, 89.0, 90.0, 95.0, 100.0}) {
    const double ts = zd * kDeg, K = std::min(0.5, ts / kPi);
    // Row v = K is the view zenith angle K pi (the sun's own for theta_s <= 90 deg).
    for (double u : {0.0, 0.3, 1.0}) EXPECT_NEAR(std::acos(m.Direction(u, K, ts)[2]), K * kPi, 1e-9);
    // u = 0 faces the sun's azimuth, u = 1 the opposite azimuth, u^2 in between.
    const std::array<double, 3> d0 = m.Direction(0.0, 0.3, ts), d1 = m.Direction(1.0, 0.3, ts), dh = m.Direction(0.5, 0.3, ts);
    EXPECT_GT(d0[0], 0.0);
    EXPECT_NEAR(d0[1], 0.0, 1e-15);
    EXPECT_LT(d1[0], 0.0);
    EXPECT_NEAR(std::atan2(dh[1], dh[0]), kPi / 4, 1e-12);
  }
}

TEST(Gt7Sphere, UvToDirectionToUvWithin1e5TexelEverywhere) {
  const SphereMapping m;
  double worst = 0.0;
  std::string where;
  // A dense grid of the open square plus rows next to the horizon (v = 0.8), the K rows and the
  // edges, at sun zenith angles on both sides of the threshold and of 90 deg.
  std::vector<double> vs, us;
  for (int i = 1; i < 400; ++i) vs.push_back(i / 400.0);
  for (double e : {1e-3, 1e-5, 1e-7, 1e-9}) {
    for (double c : {0.5, 0.8, 75.0 / 180.0, 87.0 / 180.0, 0.49, 0.5}) {
      vs.push_back(c - e);
      vs.push_back(c + e);
    }
    vs.push_back(e < 1e-3 ? 1e-3 : e);
    vs.push_back(1.0 - 1e-3);
  }
  for (int i = 0; i <= 200; ++i) us.push_back(i / 200.0);
  for (int x = 0; x < kW; ++x) us.push_back((x + 0.5) / kW);
  for (int y = 0; y < kH; ++y) vs.push_back((y + 0.5) / kH);
  for (double zd : SunZenithsDeg()) {
    const double ts = zd * kDeg;
    for (double v : vs) {
      for (double u : us) {
        const std::array<double, 3> d = m.Direction(u, v, ts);
        ASSERT_NEAR(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], 1.0, 1e-12);
        const std::array<double, 2> uv = m.Uv(d, ts);
        const double err = std::max(std::fabs(uv[0] - u) * kW, std::fabs(uv[1] - v) * kH);
        if (err > worst) {
          worst = err;
          where = "sun zenith " + std::to_string(zd) + " u " + std::to_string(u) + " v " + std::to_string(v);
        }
      }
    }
  }
  SKYBAKE_LOG("worst uv -> direction -> uv error: %.3g texel (%s)\n", worst, where.c_str());
  EXPECT_LT(worst, 1e-5) << where;
}

TEST(Gt7Sphere, DirectionToUvToDirectionIsExact) {
  const SphereMapping m;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n;
  double worst = 0.0;
  for (double zd : SunZenithsDeg()) {
    for (int k = 0; k < 20000; ++k) {
      std::array<double, 3> d = {n(rng), std::fabs(n(rng)), n(rng)};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double& c : d) c /= len;
      const std::array<double, 2> uv = m.Uv(d, zd * kDeg);
      worst = std::max(worst, Angle(m.Direction(uv[0], uv[1], zd * kDeg), d));
    }
  }
  EXPECT_LT(worst, 1e-9);
  // The mirror image (y < 0) maps to the same texel.
  const std::array<double, 3> d = {0.3, -0.4, std::sqrt(1 - 0.25)}, dm = {0.3, 0.4, std::sqrt(1 - 0.25)};
  EXPECT_EQ(m.Uv(d, 0.5), m.Uv(dm, 0.5));
}

TEST(Gt7Sphere, EachFamilyIsContinuousInTheSunAngleUpToTheThreshold) {
  // Slices are read with their own family at the target sun angle (lut/decoder.h), so each
  // family must vary smoothly with theta_s: a step of 1e-6 rad moves no texel by more than a
  // few 1e-6 rad of direction (sun-aligned up to and beyond the threshold, lat-long everywhere).
  const SphereMapping m;
  const double thr = m.ThresholdZenithRad();
  for (double ts : {thr - 0.05, thr - 1e-6, thr, thr + 0.02}) {
    for (SphereFamily f : {SphereFamily::kSunAligned, SphereFamily::kLatLong}) {
      for (int y = 0; y < kH; y += 7) {
        for (int x = 0; x < kW; x += 3) {
          const double u = (x + 0.5) / kW, v = (y + 0.5) / kH;
          const double a = Angle(SphereMapping::DirectionIn(f, u, v, ts), SphereMapping::DirectionIn(f, u, v, ts + 1e-6));
          EXPECT_LT(a, 1e-4) << SphereFamilyName(f) << " " << ts << " " << u << " " << v;
        }
      }
    }
  }
  EXPECT_EQ(m.FamilyFor(thr), SphereFamily::kSunAligned);
  EXPECT_EQ(m.FamilyFor(std::nextafter(thr, 10.0)), SphereFamily::kLatLong);
  EXPECT_NEAR(thr, 75.0 * kDeg, 1e-15);
}

TEST(Gt7Sphere, SkyMappingFactoryAndTexels) {
  std::unique_ptr<SkyMapping> g = MakeSkyMapping("gt7", kW, kH);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->Name(), "gt7");
  EXPECT_EQ(g->width(), kW);
  EXPECT_EQ(g->height(), kH);
  EXPECT_NE(std::find(SkyMappingNames().begin(), SkyMappingNames().end(), "gt7"), SkyMappingNames().end());
  // Every texel is its own mirror; texel directions are the mapping at the texel centres.
  const SphereMapping m;
  for (int y = 0; y < kH; y += 5) {
    for (int x = 0; x < kW; x += 3) {
      EXPECT_EQ(g->Mirror(x, y), (std::array<int, 2>{x, y}));
      for (double zd : {30.0, 95.0}) {
        const std::array<double, 3> d = *g->TexelDirection(x, y, zd * kDeg);
        EXPECT_LT(Angle(d, m.Direction((x + 0.5) / kW, (y + 0.5) / kH, zd * kDeg)), 1e-15);
      }
    }
  }
  // Texels crowd at the sun and at the horizon: the rows just above and below the horizon cover
  // a smaller angle than rows at mid-sky (sun at 30 deg elevation, u = 1/2).
  const double ts = 60.0 * kDeg;
  auto row_angle = [&](int y) { return Angle(m.Direction(0.5, (y + 0.0) / kH, ts), m.Direction(0.5, (y + 1.0) / kH, ts)); };
  EXPECT_LT(row_angle(101), row_angle(80) / 4);   // just above the horizon row (v = 0.8 = 102.4/128)
  EXPECT_LT(row_angle(103), row_angle(120) / 2);  // just below it
  EXPECT_LT(row_angle(0), row_angle(40) / 10);    // at the sun
}
