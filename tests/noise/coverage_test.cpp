// The coverage texture (noise/coverage.h): closed-form texels from the authored curves, no cloud
// at zero density or outside a type's vertical extent, taller clouds at higher density, YAML errors.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/error.h"
#include "noise/coverage.h"

using namespace skybake;
using namespace skybake::noise;

namespace {

CloudType Humilis() {
  CloudType t;
  t.name = "humilis";
  t.base_m = 1000.0;
  t.top_at_zero_density_m = 1400.0;
  t.top_at_full_density_m = 2600.0;
  t.height_modulation = Curve{{0.0, 0.1, 0.5, 1.0}, {0.0, 1.0, 0.9, 0.0}};
  t.low_frequency = Curve{{0.0, 1.0}, {1.0, 0.7}};
  t.mid_frequency = Curve{{0.0, 1.0}, {0.3, 0.6}};
  t.ambient = Curve{{0.0, 1.0}, {0.35, 1.0}};
  return t;
}

std::string YamlErrors(const std::string& text) {
  try {
    ParseCoverageSpec(YamlDocument::Parse(text, "cov.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Coverage, CurvesInterpolateLinearlyAndClamp) {
  const Curve c{{0.0, 0.1, 0.5, 1.0}, {0.0, 1.0, 0.9, 0.0}};
  EXPECT_DOUBLE_EQ(c(0.05), 0.5);
  EXPECT_DOUBLE_EQ(c(0.3), 0.95);
  EXPECT_DOUBLE_EQ(c(0.75), 0.45);
  EXPECT_DOUBLE_EQ(c(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(c(2.0), 0.0);
  EXPECT_DOUBLE_EQ(c(0.1), 1.0);
}

TEST(Coverage, TexelsFollowTheClosedForm) {
  const CloudType t = Humilis();
  // d = 0.5: top = 1.4 + 1.2 * 0.5 = 2.0 km; z = 1.3 km -> s = 0.3 -> h = 0.95, w_L = 0.91,
  // w_M = 0.39, a = 0.545; fade e(0.5) = 1 with d_fade = 0.1.
  const std::array<double, 4> v = CoverageAt(t, 0.1, 0.5, 1300.0);
  EXPECT_NEAR(v[0], 0.5 * 0.95, 1e-12);
  EXPECT_NEAR(v[1], 0.91, 1e-12);
  EXPECT_NEAR(v[2], 0.39, 1e-12);
  EXPECT_NEAR(v[3], 0.545, 1e-12);
  // d = 0.05 is half way through the fade-in: e = smoothstep(0.5) = 0.5.
  const std::array<double, 4> w = CoverageAt(t, 0.1, 0.05, 1100.0);
  const double s = 100.0 / (1400.0 + 60.0 - 1000.0);
  EXPECT_NEAR(w[1], 0.5 * (1.0 - 0.3 * s), 1e-12);
  EXPECT_NEAR(w[0], 0.05 * t.height_modulation(s), 1e-12);
}

TEST(Coverage, NoCloudAtZeroDensityOrOutsideTheLayer) {
  const CloudType t = Humilis();
  for (double z = 0.0; z <= 9000.0; z += 250.0) {
    const std::array<double, 4> v = CoverageAt(t, 0.1, 0.0, z);
    EXPECT_EQ(v[0], 0.0);
    EXPECT_EQ(v[1], 0.0);
    EXPECT_EQ(v[2], 0.0);
  }
  for (double d : {0.2, 0.7, 1.0}) {
    const double top = 1400.0 + 1200.0 * d;
    for (double z : {0.0, 999.0, top + 1.0, 5000.0}) {
      const std::array<double, 4> v = CoverageAt(t, 0.1, d, z);
      EXPECT_EQ(v[0], 0.0) << d << " " << z;
      EXPECT_EQ(v[1], 0.0);
      EXPECT_EQ(v[2], 0.0);
      // Ambient is the curve's end value outside the cloud (below: a(0), above: a(1)).
      EXPECT_DOUBLE_EQ(v[3], z < 1000.0 ? 0.35 : 1.0);
    }
  }
}

TEST(Coverage, TextureLayoutAndTallerCloudsAtHigherDensity) {
  CoverageSpec spec;
  spec.types = {Humilis(), Humilis()};
  spec.types[1].name = "tall";
  spec.types[1].top_at_full_density_m = 6000.0;
  const CoverageTexture tex = BuildCoverageTexture(spec);
  ASSERT_EQ(tex.width, 256);
  ASSERT_EQ(tex.height, 128);
  ASSERT_EQ(tex.layers, 2);
  // Columns hold d_i = i / 255 and rows z_j = 0.5 km + j * 8 km / 127 exactly.
  EXPECT_EQ(spec.ColumnDensity(255), 1.0);
  EXPECT_EQ(spec.RowAltitudeM(127), 8500.0);
  const std::array<double, 4> v = CoverageAt(spec.types[1], spec.noise_fade_in_density, 200.0 / 255.0, spec.RowAltitudeM(40));
  for (int c = 0; c < 4; ++c) EXPECT_EQ(tex.At(1, 200, 40, c), static_cast<float>(v[c]));
  // The highest cloudy row rises with density, and the tall type reaches higher.
  auto top_row = [&](int layer, int column) {
    int top = -1;
    for (int j = 0; j < tex.height; ++j)
      if (tex.At(layer, column, j, 0) > 0.0f) top = j;
    return top;
  };
  int previous = -1;
  for (int i = 1; i < 256; i += 25) {
    EXPECT_GE(top_row(0, i), previous);
    previous = top_row(0, i);
  }
  EXPECT_GT(top_row(1, 255), top_row(0, 255));
  for (int j = 0; j < tex.height; ++j) EXPECT_EQ(tex.At(0, 0, j, 0), 0.0f);  // d = 0: no cloud
}

TEST(CoverageYaml, ErrorsAreLocatedWordForWord) {
  const std::string head = "texture: {density_texels: 256, altitude_texels: 128}\naltitude_km: {bottom: 0.5, top: 8.5}\ntypes:\n";
  const std::string curves =
      "    height_modulation: [[0, 0], [0.1, 1], [1, 0]]\n    low_frequency: [[0, 1], [1, 1]]\n"
      "    mid_frequency: [[0, 0.3], [1, 0.6]]\n    ambient: [[0, 0.3], [1, 1]]\n";
  EXPECT_EQ(YamlErrors(head + "  - name: a\n    base_km: 1\n    top_km: {at_zero_density: 2, at_full_density: 3}\n" + curves), "");
  EXPECT_EQ(YamlErrors(head + "  - name: a\n    base_km: 1\n    top_km: {at_zero_density: 0.8, at_full_density: 3}\n" + curves),
            "cov.yaml:6: key 'types[0].top_km': at_zero_density (0.8 km) must be above base_km (1 km)");
  EXPECT_EQ(YamlErrors(head + "  - name: a\n    base_km: 1\n    top_km: {at_zero_density: 2, at_full_density: 9}\n" + curves),
            "cov.yaml:6: key 'types[0].top_km': the cloud spans 1 to 9 km but the texture covers 0.5 to 8.5 km (altitude_km)");
  std::string bad_curve = curves;
  bad_curve.replace(bad_curve.find("[[0, 1], [1, 1]]"), 16, "[[0, 1], [0.5, 1]]");
  EXPECT_EQ(YamlErrors(head + "  - name: a\n    base_km: 1\n    top_km: {at_zero_density: 2, at_full_density: 3}\n" + bad_curve),
            "cov.yaml:8: key 'types[0].low_frequency': the curve must start at height fraction 0 and end at 1");
  bad_curve = curves;
  bad_curve.replace(bad_curve.find("[0.1, 1]"), 8, "[0, 1]");
  EXPECT_EQ(YamlErrors(head + "  - name: a\n    base_km: 1\n    top_km: {at_zero_density: 2, at_full_density: 3}\n" + bad_curve),
            "cov.yaml:7: key 'types[0].height_modulation[1]': height fractions must increase strictly (0 after 0)");
}

TEST(CoverageYaml, RepositoryFileLoadsAndRoundTrips) {
  const CoverageSpec s = LoadCoverageSpec(std::filesystem::path(SKYBAKE_SOURCE_DIR) / "clouds/coverage.yaml");
  EXPECT_EQ(s.density_texels, 256);
  EXPECT_EQ(s.altitude_texels, 128);
  EXPECT_EQ(s.types.size(), 3u);
  const CoverageSpec back = ParseCoverageSpec(YamlDocument::Parse(CanonicalCoverageYaml(s), "canonical.yaml"));
  EXPECT_EQ(CanonicalCoverageYaml(back), CanonicalCoverageYaml(s));
}
