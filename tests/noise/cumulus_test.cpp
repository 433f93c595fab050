// The cumulus map (noise/cumulus.h): the nonlinear texel mapping and its inverse, advection as a
// world-space shift, coverage and type statistics, determinism, YAML errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "io/error.h"
#include "noise/cumulus.h"
#include "support/threads.h"

using namespace skybake;
using namespace skybake::noise;

namespace {

CumulusSpec TestSpec() {
  CumulusSpec s;
  s.resolution = 256;
  s.size_m = 240e3;
  s.edge_to_centre_ratio = 4.0;
  s.weather.seed = 99;
  s.weather.coverage = 0.45;
  s.weather.density = FbmSpec{40e3, 4, 2.0, 0.5};
  s.weather.type = FbmSpec{120e3, 2, 2.0, 0.5};
  return s;
}

// Bilinear interpolation of channel c of `map` at world point (x, y), in texture space (u), as a
// GPU samples it; nullopt outside the span of texel centres.
std::optional<double> Sample(const CumulusMap& map, const CumulusMapping& m, double x, double y, int c) {
  const double tx = m.TexelCoord(x) - 0.5, ty = m.TexelCoord(y) - 0.5;
  const int n = map.resolution;
  if (!(tx >= 0.0 && ty >= 0.0 && tx <= n - 1 && ty <= n - 1)) return std::nullopt;
  const int i = std::min(static_cast<int>(tx), n - 2), j = std::min(static_cast<int>(ty), n - 2);
  const double fx = tx - i, fy = ty - j;
  const double a = map.At(i, j, c) + fx * (map.At(i + 1, j, c) - map.At(i, j, c));
  const double b = map.At(i, j + 1, c) + fx * (map.At(i + 1, j + 1, c) - map.At(i, j + 1, c));
  return a + fy * (b - a);
}

std::string YamlErrors(const std::string& text) {
  try {
    ParseCumulusSpec(YamlDocument::Parse(text, "c.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// ---------------------------------------------------------------------------- mapping

TEST(CumulusMapping, RoundTripsAndIsMonotone) {
  for (double ratio : {1.0, 1.5, 4.0, 20.0}) {
    const CumulusMapping m(256, 120e3, ratio);
    double previous = -std::numeric_limits<double>::infinity();
    for (int t = 0; t <= 2000; ++t) {
      const double u = -1.0 + t / 1000.0;
      const double x = m.WorldFromU(u);
      EXPECT_NEAR(m.UFromWorld(x), u, 1e-12) << ratio;
      EXPECT_NEAR(m.WorldFromU(m.UFromWorld(x)), x, 1e-7) << ratio;  // m: 1e-12 relative of 120 km
      EXPECT_GT(x, previous);
      EXPECT_NEAR(m.WorldFromU(-u), -x, 1e-9);  // odd
      previous = x;
    }
    EXPECT_NEAR(m.WorldFromU(1.0), 120e3, 1e-6);
    EXPECT_NEAR(m.WorldFromU(-1.0), -120e3, 1e-6);
    EXPECT_EQ(m.WorldFromU(0.0), 0.0);
  }
}

TEST(CumulusMapping, TexelSizesAtCentreAndEdge) {
  // h(u) = (2/N) R a cosh(a u)/sinh(a), a = acosh(r): h(edge)/h(centre) = r. For GT7's map (N = 256,
  // R = 120 km) with r = 4: a = 2.0634, h(centre) = 0.49948 km, h(edge) = 1.99791 km.
  const CumulusMapping m(256, 120e3, 4.0);
  EXPECT_NEAR(m.a(), 2.0634370688955608, 1e-12);
  EXPECT_NEAR(m.TexelSizeM(0.0), 499.47858773622195, 1e-6);
  EXPECT_NEAR(m.TexelSizeM(1.0), 1997.9143509448882, 1e-6);
  EXPECT_NEAR(m.TexelSizeM(1.0) / m.TexelSizeM(0.0), 4.0, 1e-12);
  // dx/du against central differences, and the uniform limit r = 1: h = 2R/N everywhere.
  for (double u : {-0.9, -0.3, 0.0, 0.5, 0.99}) {
    const double h = 1e-6;
    EXPECT_NEAR(m.DxDu(u), (m.WorldFromU(u + h) - m.WorldFromU(u - h)) / (2 * h), 1e-3);
  }
  const CumulusMapping uniform(256, 120e3, 1.0);
  EXPECT_NEAR(uniform.TexelSizeM(0.7), 937.5, 1e-9);
  // Texel i's centre maps back to continuous texel coordinate i + 1/2.
  for (int i : {0, 1, 100, 255}) EXPECT_NEAR(m.TexelCoord(m.WorldFromU(m.TexelCentreU(i))), i + 0.5, 1e-9);
}

// ---------------------------------------------------------------------------- advection

TEST(CumulusMap, AdvectionIsAWorldSpaceShiftByWindTimesTime) {
  CumulusSpec s0 = TestSpec();
  s0.wind_m_s = {12.0, -5.0};
  const WeatherField field(s0.weather);
  CumulusSpec s1 = s0;
  s1.time_s = 900.0;  // shift V t = (10.8 km, -4.5 km): many texels, not a whole number of them
  const CumulusMap m0 = GenerateCumulusMap(s0, field), m1 = GenerateCumulusMap(s1, field);
  const CumulusMapping mp = s0.Mapping();
  const double sx = 12.0 * 900.0, sy = -5.0 * 900.0;

  // 1. Exactly: texel (i, j) of the map at t holds the stationary field at p - V t.
  for (int j = 0; j < 256; j += 17) {
    for (int i = 0; i < 256; i += 13) {
      const double x = mp.WorldFromU(mp.TexelCentreU(i)), y = mp.WorldFromU(mp.TexelCentreU(j));
      EXPECT_EQ(m1.At(i, j, 0), static_cast<float>(field.Density(x - sx, y - sy)));
      EXPECT_EQ(m1.At(i, j, 1), static_cast<float>(field.Type(x - sx, y - sy)));
    }
  }
  // 2. Within interpolation error: the map at t equals the map at 0 sampled (bilinearly, in
  //    texture space) at p - V t. Bilinear error <= (1/8)(du^2 |f_uu| + dv^2 |f_vv|), estimated
  //    per channel from the map's own second differences (x2 safety for the continuous maximum).
  for (int c = 0; c < 2; ++c) {
    double d2max = 0.0;
    for (int j = 1; j < 255; ++j)
      for (int i = 1; i < 255; ++i) {
        d2max = std::max(d2max, std::fabs(double{m0.At(i + 1, j, c)} - 2.0 * m0.At(i, j, c) + m0.At(i - 1, j, c)));
        d2max = std::max(d2max, std::fabs(double{m0.At(i, j + 1, c)} - 2.0 * m0.At(i, j, c) + m0.At(i, j - 1, c)));
      }
    const double bound = 2.0 * (2.0 * d2max / 8.0) + 1e-6;
    double err2 = 0.0, change2 = 0.0, errmax = 0.0;
    int count = 0;
    for (int j = 0; j < 256; ++j) {
      for (int i = 0; i < 256; ++i) {
        const double x = mp.WorldFromU(mp.TexelCentreU(i)), y = mp.WorldFromU(mp.TexelCentreU(j));
        const std::optional<double> v = Sample(m0, mp, x - sx, y - sy, c);
        if (!v) continue;
        const double e = m1.At(i, j, c) - *v;
        errmax = std::max(errmax, std::fabs(e));
        err2 += e * e;
        change2 += (m1.At(i, j, c) - m0.At(i, j, c)) * (m1.At(i, j, c) - m0.At(i, j, c));
        ++count;
      }
    }
    SCOPED_TRACE("channel " + std::to_string(c));
    EXPECT_GT(count, 256 * 256 * 3 / 4);
    EXPECT_LE(errmax, bound);
    // The shift explains the change: the residual is a small fraction of the change itself.
    EXPECT_LT(std::sqrt(err2 / count), 0.1 * std::sqrt(change2 / count));
  }
}

TEST(CumulusMap, SameBytesAtAnyThreadCount) {
  const CumulusSpec s = TestSpec();
  const WeatherField field(s.weather);
  const CumulusMap a = test::WithThreads(1, [&] { return GenerateCumulusMap(s, WeatherField(s.weather)); });
  const CumulusMap b = test::WithThreads(2, [&] { return GenerateCumulusMap(s, field); });
  ASSERT_EQ(a.values.size(), b.values.size());
  EXPECT_EQ(std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)), 0);
  CumulusSpec other = s;
  other.weather.seed = 100;
  const CumulusMap c = GenerateCumulusMap(other, WeatherField(other.weather));
  size_t same = 0;
  for (size_t i = 1; i < c.values.size(); i += 2) same += c.values[i] == a.values[i];
  EXPECT_LT(same, c.values.size() / 200);
}

// ---------------------------------------------------------------------------- statistics

TEST(WeatherField, CoverageAndDensityFollowTheRequest) {
  // P(d > 0) = c and, over the cloudy area, d = U^gamma with mean 1/(1 + gamma); the type is
  // uniform. Checked on a 400 x 400 sample spanning ~300 x 300 first-octave cells far from the
  // calibration windows (+-1e7 m): ~1e5 cells give a standard error of ~0.003 on a fraction
  // (fields are correlated over about a cell); the tolerance 0.02 is ~6 sigma.
  for (double c : {0.2, 0.45, 0.8}) {
    for (double gamma : {1.0, 2.0}) {
      WeatherSpec w = TestSpec().weather;
      w.coverage = c;
      w.density_exponent = gamma;
      const WeatherField f(w);
      const double step = 0.77 * w.density.feature_size_m;
      int covered = 0, below_quarter = 0;
      double density_sum = 0.0, type_sum = 0.0;
      const int n = 400;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const double x = -1.5e6 + i * step, y = 2.0e6 + j * step;
          const double d = f.Density(x, y), t = f.Type(x, y);
          ASSERT_GE(d, 0.0);
          ASSERT_LE(d, 1.0);
          covered += d > 0.0;
          density_sum += d;
          type_sum += t;
          below_quarter += t < 0.25;
        }
      }
      const double total = static_cast<double>(n) * n;
      SCOPED_TRACE("coverage " + std::to_string(c) + " gamma " + std::to_string(gamma));
      EXPECT_NEAR(covered / total, c, 0.02);
      EXPECT_NEAR(density_sum / covered, 1.0 / (1.0 + gamma), 0.02);
      // The type field has larger cells (120 km): 400 x 0.77 x 40/120 ~ 100 cells per side; the
      // standard error is ~0.01, tolerance 0.04.
      EXPECT_NEAR(type_sum / total, 0.5, 0.04);
      EXPECT_NEAR(below_quarter / total, 0.25, 0.04);
    }
  }
}

TEST(WeatherField, NoCoverageNoCloudFullCoverageEverywhere) {
  WeatherSpec w = TestSpec().weather;
  w.coverage = 0.0;
  const WeatherField none(w);
  w.coverage = 1.0;
  const WeatherField all(w);
  int zero = 0;
  for (int t = 0; t < 1000; ++t) {
    const double x = 3.7e3 * t, y = -1.3e3 * t;
    EXPECT_EQ(none.Density(x, y), 0.0);
    zero += all.Density(x, y) == 0.0;
  }
  EXPECT_LE(zero, 2);  // only the field's very minimum (quantile 0) gives 0 at full coverage
}

// ---------------------------------------------------------------------------- YAML

TEST(CumulusYaml, ErrorsAreLocatedWordForWord) {
  const std::string good =
      "map: {resolution: 256, size_km: 240, edge_to_centre_texel_ratio: 4}\n"
      "weather:\n  seed: 1\n  coverage: 0.4\n"
      "  density: {feature_size_km: 40, octaves: 4}\n"
      "  type: {feature_size_km: 120, octaves: 2}\n"
      "wind_m_s: [8, 3]\n";
  EXPECT_EQ(YamlErrors(good), "");
  std::string bad = good;
  bad.replace(bad.find("octaves: 4"), 10, "octaves: 6");
  EXPECT_EQ(YamlErrors(bad),
            "c.yaml:5: key 'weather.density': the finest density octave has 1.25 km cells, less than two texels "
            "at the map edge (2 x 1.998 km): it would alias; use fewer octaves, a larger feature_size_km or a "
            "smaller edge_to_centre_texel_ratio");
  bad = good;
  bad.replace(bad.find("[8, 3]"), 6, "[8]");
  EXPECT_EQ(YamlErrors(bad), "c.yaml:7: key 'wind_m_s': expected two numbers [east, north] in m/s, got a list");
  bad = good;
  bad.replace(bad.find("coverage: 0.4"), 13, "coverage: 1.4");
  EXPECT_EQ(YamlErrors(bad), "c.yaml:4: key 'weather.coverage': expected a number from 0 to 1, got \"1.4\"");
}

TEST(CumulusYaml, RepositoryFileLoads) {
  const CumulusSpec s = LoadCumulusSpec(std::filesystem::path(SKYBAKE_SOURCE_DIR) / "clouds/cumulus.yaml");
  EXPECT_EQ(s.resolution, 256);
  EXPECT_EQ(s.size_m, 240e3);
  EXPECT_EQ(s.wind_m_s[0], 8.0);
  // The canonical form reads back to the same spec.
  const CumulusSpec back = ParseCumulusSpec(YamlDocument::Parse(CanonicalCumulusYaml(s), "canonical.yaml"));
  EXPECT_EQ(CanonicalCumulusYaml(back), CanonicalCumulusYaml(s));
}
