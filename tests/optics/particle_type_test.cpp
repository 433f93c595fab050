// Particle types: the log-normal algebra, the loader's word-for-word errors (file:line), the
// refractive-index tables, and the canonical file the generator writes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "io/error.h"
#include "optics/particle_type.h"

namespace fs = std::filesystem;
using namespace skybake;
using namespace skybake::mie;

namespace {

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() / ("skybake_particle_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  fs::path Write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  static inline int counter_ = 0;
};

const char* kIndexCsv =
    "# source: test table\n"
    "component,wavelength_um,n_real,k_imag\n"
    "a,0.30,1.50,0.010\n"
    "a,0.50,1.48,0.001\n"
    "a,0.90,1.46,0.000\n"
    "b,0.30,1.33,1e-8\n"
    "b,0.90,1.32,1e-7\n";

// A valid one-mode type; `mode_extra` replaces the mode's body after its name.
std::string Type(const std::string& mode_body) {
  return "refractive_index: {table: index.csv, select: {component: a}}\n"
         "modes:\n"
         "  - name: fine\n" +
         mode_body;
}

const std::string kGoodMode =
    "    basis: volume\n"
    "    median_radius_um: 0.12\n"
    "    ln_sigma_g: 0.45\n"
    "    r_min_um: 0.05\n"
    "    r_max_um: 15\n"
    "    weight: {relative_volume: 1.0}\n";

// The error text of loading `yaml` (written as t.yaml beside index.csv), "" if it loads.
std::string LoadErrors(const TempDir& dir, const std::string& yaml) {
  dir.Write("index.csv", kIndexCsv);
  const fs::path p = dir.Write("t.yaml", yaml);
  try {
    LoadParticleType(p);
  } catch (const InputError& e) {
    std::string out;
    for (const Diagnostic& d : e.diagnostics()) out += d.ToString() + "\n";
    return out;
  }
  return "";
}

}  // namespace

// Hatch-Choate relations of the log-normal (Hansen & Travis 1974, eqs. 2.53-2.56)
// against a direct numerical integration of the truncated distribution.
TEST(ParticleType, LogNormalAlgebraMatchesNumericalMoments) {
  TempDir dir;
  dir.Write("index.csv", kIndexCsv);
  const ParticleType t = LoadParticleType(dir.Write("t.yaml", Type(kGoodMode)));
  const SizeMode& m = t.modes[0];
  const double s = 0.45;
  EXPECT_NEAR(m.NumberMedianRadiusUm(), 0.12 * std::exp(-3.0 * s * s), 1e-15);
  EXPECT_NEAR(m.VolumeMedianRadiusUm(), 0.12, 1e-15);
  EXPECT_NEAR(m.EffectiveRadiusUm(), 0.12 * std::exp(-0.5 * s * s), 1e-15);
  EXPECT_NEAR(m.EffectiveVariance(), std::exp(s * s) - 1.0, 1e-15);
  // Moments of the truncated distribution by a fine trapezoid in ln r.
  const double rg = m.NumberMedianRadiusUm();
  const int n = 200000;
  const double a = std::log(0.05), b = std::log(15.0);
  double z = 0.0, r3 = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double u = a + (b - a) * i / n;
    const double w = (i == 0 || i == n ? 0.5 : 1.0) * std::exp(-0.5 * std::pow((u - std::log(rg)) / s, 2)) /
                     (std::sqrt(2.0 * std::numbers::pi) * s) * (b - a) / n;
    z += w;
    r3 += w * std::exp(3.0 * u);
  }
  EXPECT_NEAR(m.NumberFractionInside(), z, 1e-9);
  EXPECT_NEAR(m.MomentInsideUm(3), r3 / z, 1e-9 * r3 / z);
}

// Volume weights become number fractions through each mode's mean particle volume.
TEST(ParticleType, VolumeWeightsConvertToNumberFractions) {
  TempDir dir;
  const std::string two = Type(kGoodMode) +
                          "  - name: coarse\n"
                          "    basis: volume\n"
                          "    median_radius_um: 4.0\n"
                          "    ln_sigma_g: 0.55\n"
                          "    r_min_um: 0.05\n"
                          "    r_max_um: 15\n"
                          "    weight: {relative_volume: 2.0}\n";
  dir.Write("index.csv", kIndexCsv);
  const ParticleType t = LoadParticleType(dir.Write("t.yaml", two));
  const std::vector<double> f = t.NumberFractions();
  const double n0 = 1.0 / t.modes[0].MeanVolumeInsideUm3(), n1 = 2.0 / t.modes[1].MeanVolumeInsideUm3();
  EXPECT_NEAR(f[0], n0 / (n0 + n1), 1e-15);
  EXPECT_NEAR(f[1], n1 / (n0 + n1), 1e-15);
  // The mixture's mean volume splits the total volume 1 : 2 between the modes.
  EXPECT_NEAR(f[1] * t.modes[1].MeanVolumeInsideUm3() / (f[0] * t.modes[0].MeanVolumeInsideUm3()), 2.0, 1e-12);
}

TEST(ParticleType, RefractiveIndexInterpolation) {
  TempDir dir;
  dir.Write("index.csv", kIndexCsv);
  const ParticleType t = LoadParticleType(dir.Write("t.yaml", Type(kGoodMode)));
  const RefractiveIndex& ri = t.modes[0].index;
  // n linear in wavelength; k log-linear (0.01 -> 0.001 between 300 and 500 nm: sqrt at 400 nm);
  // an interval with k = 0 at one end is linear.
  EXPECT_NEAR(ri.At(400.0).real(), 1.49, 1e-15);
  EXPECT_NEAR(ri.At(400.0).imag(), std::sqrt(0.01 * 0.001), 1e-15);
  EXPECT_NEAR(ri.At(700.0).imag(), 0.0005, 1e-15);
  EXPECT_TRUE(ri.Covers(300.0, 900.0));
  EXPECT_FALSE(ri.Covers(299.0, 900.0));
}

// Every bad input of the issue, word for word, with file:line.
TEST(ParticleType, BadInputsAreReportedWithFileAndLine) {
  TempDir dir;
  const std::string f = (dir.path() / "t.yaml").string();
  auto with = [&](const std::string& from, const std::string& to) {
    std::string body = kGoodMode;
    body.replace(body.find(from), from.size(), to);
    return LoadErrors(dir, Type(body));
  };
  EXPECT_EQ(LoadErrors(dir, Type(kGoodMode)), "");
  EXPECT_EQ(with("median_radius_um: 0.12", "median_radius_um: -0.12"),
            f + ":5: key 'modes[0].median_radius_um': expected a number from 1e-04 to 100 in um, got \"-0.12\"\n");
  EXPECT_EQ(with("median_radius_um: 0.12", "median_radius_um: 0"),
            f + ":5: key 'modes[0].median_radius_um': expected a number from 1e-04 to 100 in um, got \"0\"\n");
  EXPECT_EQ(with("r_min_um: 0.05", "r_min_um: -1"),
            f + ":7: key 'modes[0].r_min_um': expected a number from 1e-04 to 100 in um, got \"-1\"\n");
  EXPECT_EQ(with("ln_sigma_g: 0.45", "ln_sigma_g: 0"),
            f + ":6: key 'modes[0].ln_sigma_g': expected a number from 0.0001 to 1.609 (ln 5), got \"0\"\n");
  EXPECT_EQ(with("ln_sigma_g: 0.45", "sigma_g: 1.0"),
            f + ":6: key 'modes[0].sigma_g': expected a number from 1.0001 to 5, got \"1.0\"\n");
  EXPECT_EQ(with("ln_sigma_g: 0.45", "sigma_g: 0.45"),
            f + ":6: key 'modes[0].sigma_g': expected a number from 1.0001 to 5, got \"0.45\"\n");
  EXPECT_EQ(with("r_max_um: 15", "r_max_um: 0.05"),
            f + ":8: key 'modes[0].r_max_um': must be greater than r_min_um (0.05 <= 0.05)\n");
  EXPECT_EQ(with("median_radius_um: 0.12", "median_radius_um: .nan"),
            f + ":5: key 'modes[0].median_radius_um': expected a number from 1e-04 to 100 in um, got \".nan\"\n");
  EXPECT_EQ(with("r_max_um: 15", "r_max_um: nan"),
            f + ":8: key 'modes[0].r_max_um': expected a number from 1e-04 to 100 in um, got \"nan\"\n");
  // Above the stated ranges (docs/mie.md "Valid ranges"): a size parameter without end, a
  // distribution wider than the radius range.
  EXPECT_EQ(with("r_max_um: 15", "r_max_um: 1e20"),
            f + ":8: key 'modes[0].r_max_um': expected a number from 1e-04 to 100 in um, got \"1e20\"\n");
  EXPECT_EQ(with("ln_sigma_g: 0.45", "sigma_g: 1e9"),
            f + ":6: key 'modes[0].sigma_g': expected a number from 1.0001 to 5, got \"1e9\"\n");
  EXPECT_EQ(with("basis: volume", "basis: volume\n    sigma: 2.0"),
            f + ":5: unknown key 'modes[0].sigma' (did you mean 'sigma_g'?)\n");
  EXPECT_EQ(with("ln_sigma_g: 0.45", "ln_sigma_g: 0.45\n    sigma_g: 1.5"),
            f + ":3: 'modes[0]' needs exactly one of 'sigma_g' or 'ln_sigma_g', got sigma_g and ln_sigma_g\n");
  EXPECT_EQ(with("    basis: volume\n", ""), f + ":3: missing key 'modes[0].basis': expected one of 'number' or 'volume'\n");
  EXPECT_EQ(with("weight: {relative_volume: 1.0}", "weight: {relative_volume: 1.0, relative_number: 1}"),
            f + ":9: 'modes[0].weight' needs exactly one of 'number_density_cm3', 'relative_number', "
                "'volume_um3_per_cm3' or 'relative_volume', got relative_number and relative_volume\n");
  // A mode whose bounds hold (almost) none of its particles.
  EXPECT_EQ(with("r_min_um: 0.05", "r_min_um: 14"),
            f + ":3: mode 'fine': [r_min_um, r_max_um] = [14, 15] holds only 3.64e-33 of its particles (number "
                "median radius 0.0653653 um)\n");
}

TEST(ParticleType, MixedWeightKeysAndMissingIndexAreErrors) {
  TempDir dir;
  const std::string f = (dir.path() / "t.yaml").string();
  EXPECT_EQ(LoadErrors(dir, Type(kGoodMode) +
                                "  - name: coarse\n"
                                "    basis: number\n"
                                "    median_radius_um: 2\n"
                                "    sigma_g: 2\n"
                                "    r_min_um: 0.05\n"
                                "    r_max_um: 15\n"
                                "    weight: {number_density_cm3: 3}\n"),
            f + ":16: key 'modes[1].weight': every mode must give its weight with the same key "
                "('relative_volume' in mode 'fine', 'number_density_cm3' here)\n");
  std::string no_index = Type(kGoodMode);
  no_index.erase(0, no_index.find('\n') + 1);
  EXPECT_EQ(LoadErrors(dir, no_index),
            f + ":2: missing key 'modes[0].refractive_index': expected a refractive index (the type gives no default)\n");
}

TEST(ParticleType, BadRefractiveIndexTablesAreLocatedInTheCsv) {
  TempDir dir;
  const std::string csv = (dir.path() / "bad.csv").string();
  dir.Write("bad.csv", "# source: test\nwavelength_nm,n_real,k_imag\n400,1.5,0.01\n300,1.5,-0.01\n500,-1,0\n");
  const std::string yaml = "refractive_index: {table: bad.csv}\nmodes:\n  - name: fine\n" + kGoodMode;
  EXPECT_EQ(LoadErrors(dir, yaml),
            csv + ":4: column 'wavelength_nm': wavelengths must increase strictly (300 after 400)\n" + csv +
                ":4: column 'k_imag': k must be from 0 to 3 (m = n + ik; absorbing media have k > 0), got -0.01\n" + csv +
                ":5: column 'n_real': the real part n must be from 1 to 3, got -1\n");
  const std::string f = (dir.path() / "t.yaml").string();
  EXPECT_EQ(LoadErrors(dir, "refractive_index: {table: index.csv, select: {component: zz}}\nmodes:\n  - name: fine\n" +
                                kGoodMode),
            f + ":1: select: no row of " + (dir.path() / "index.csv").string() + " has component = 'zz'\n");
}

// A wavelength outside the refractive-index table: located at the refractive_index key.
TEST(ParticleType, WavelengthOutsideTheIndexTable) {
  TempDir dir;
  dir.Write("index.csv", kIndexCsv);
  const fs::path p = dir.Write("t.yaml", Type(kGoodMode));
  const ParticleType t = LoadParticleType(p);
  try {
    CheckWavelengthCoverage(t, 250.0, 830.0);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ":1: mode 'fine': the refractive index covers wavelengths 300-900 nm of " +
                                         (dir.path() / "index.csv").string() + ", the wavelength grid needs 250-830 nm");
  }
  EXPECT_NO_THROW(CheckWavelengthCoverage(t, 360.0, 830.0));
}

// The canonical file: equal content gives equal bytes (comments, key order, spelling of numbers
// and of paths do not matter), it loads back to the same type, and its paths are relative.
TEST(ParticleType, CanonicalYamlIsStableAndLoadsBack) {
  TempDir dir;
  dir.Write("index.csv", kIndexCsv);
  const ParticleType a = LoadParticleType(dir.Write("t.yaml", Type(kGoodMode)));
  const ParticleType b = LoadParticleType(dir.Write(
      "other/t.yaml",
      "# a comment\nmodes:\n  - weight: {relative_volume: 1.00}\n    name: fine\n    r_max_um: 1.5e1\n"
      "    r_min_um: 0.050\n    ln_sigma_g: 0.45\n    median_radius_um: 0.12\n    basis: volume\n"
      "refractive_index:\n  table: ../sub/../index.csv\n  select: {component: a}\n"));
  const fs::path out = dir.path() / "components" / "particles";
  const std::string ca = CanonicalParticleYaml(a, out), cb = CanonicalParticleYaml(b, out);
  EXPECT_EQ(ca, cb);
  EXPECT_NE(ca.find("table: ../../index.csv"), std::string::npos) << ca;
  const fs::path written = dir.Write("components/particles/t.yaml", ca);
  const ParticleType c = LoadParticleType(written);
  EXPECT_EQ(CanonicalParticleYaml(c, out), ca);
  EXPECT_EQ(c.name, "t");
  EXPECT_DOUBLE_EQ(c.modes[0].index.At(550.0).real(), a.modes[0].index.At(550.0).real());
}

// The shipped types load, cover the pipeline's grid, and have the documented derived values.
TEST(ParticleType, ShippedTypesLoad) {
  for (const char* name : {"gt7_case_study", "continental", "water_cloud", "gt7_case_study_22_bins"}) {
    SCOPED_TRACE(name);
    const ParticleType t = LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / (std::string(name) + ".yaml"));
    EXPECT_NO_THROW(CheckWavelengthCoverage(t, 360.0, 830.0));
    double total = 0.0;
    for (double f : t.NumberFractions()) total += f;
    EXPECT_NEAR(total, 1.0, 1e-12);
  }
  const ParticleType gt7 = LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "gt7_case_study.yaml");
  ASSERT_EQ(gt7.modes.size(), 5u);
  // The talk's numbers as read (particles/gt7_case_study.yaml): volume medians and ln sigma_g.
  EXPECT_DOUBLE_EQ(gt7.modes[4].VolumeMedianRadiusUm(), 4.0);
  EXPECT_DOUBLE_EQ(gt7.modes[4].LnSigma(), 0.55);
  EXPECT_DOUBLE_EQ(gt7.modes[2].weight, 0.74);
  const ParticleType cloud = LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "water_cloud.yaml");
  EXPECT_NEAR(cloud.modes[0].EffectiveRadiusUm(), 10.0, 1e-12);
  EXPECT_NEAR(cloud.modes[0].EffectiveVariance(), 0.1, 1e-4);
}
