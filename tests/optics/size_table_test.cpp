// Tabulated size distributions (optics/size_table.h) and refractive indices from a few points:
// a table sampled from a log-normal mode reproduces the mode's optics, the exact moments, the
// loader's errors at file:line, and the points' interpolation and extrapolation rules.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "io/error.h"
#include "io/yaml.h"
#include "optics/particle_type.h"
#include "optics/polydisperse.h"

namespace fs = std::filesystem;
using namespace skybake;
using namespace skybake::mie;

namespace {

constexpr double kPi = std::numbers::pi;

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() / ("skybake_size_table_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  fs::path Write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    std::ofstream(p) << text;
    return p;
  }

 private:
  fs::path path_;
  static inline int counter_ = 0;
};

// dV/d ln r of a volume log-normal (r_V, s) at `rows` radii log-spaced over [r_min, r_max].
std::string SampledCsv(double r_v, double s, double r_min, double r_max, int rows) {
  std::string csv = "# source: sampled from a log-normal (test)\nradius_um,dV_dlnr_um3_um2\n";
  for (int i = 0; i < rows; ++i) {
    const double u = std::log(r_min) + (std::log(r_max) - std::log(r_min)) * i / (rows - 1);
    const double z = (u - std::log(r_v)) / s;
    csv += FormatExact(std::exp(u)) + "," + FormatExact(std::exp(-0.5 * z * z)) + "\n";
  }
  return csv;
}

std::string LoadErrors(const fs::path& yaml) {
  try {
    LoadParticleType(yaml);
  } catch (const InputError& e) {
    std::string out;
    for (const Diagnostic& d : e.diagnostics()) out += d.ToString() + "\n";
    return out;
  }
  return "";
}

// L1 distance int |P_a - P_b| dOmega on the grid (trapezoid in mu).
double PhaseL1(const PhaseGrid& grid, const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (size_t j = 0; j + 1 < grid.size(); ++j) {
    d += kPi * (grid.mu[j] - grid.mu[j + 1]) * (std::abs(a[j] - b[j]) + std::abs(a[j + 1] - b[j + 1]));
  }
  return d;
}

}  // namespace

// The table's interpolation and the quadrature over it are right: a volume table sampled at
// 1200 radii (spacing 0.0048 in ln r, interpolation error ~ h^2/(12 s^2) ~ 1e-5) from the GT7
// fine mode reproduces the mode's C_ext, C_sca, C_abs (relative to C_ext), albedo, g and phase
// function (L1) within 1e-4, for a weakly and a strongly absorbing index, both integrated to 1e-5.
TEST(SizeTable, TableSampledFromALogNormalReproducesTheMode) {
  TempDir dir;
  dir.Write("fine.csv", SampledCsv(0.12, 0.45, 0.05, 15.0, 1200));
  for (const std::string index : {"{n: 1.33, k: 1e-8}", "{n: 1.75, k: 0.44}"}) {
    const fs::path table_yaml = dir.Write("table.yaml", "refractive_index: " + index +
                                                            "\nmodes:\n  - name: fine\n    size_table: fine.csv\n"
                                                            "    weight: {relative_volume: 1}\n");
    const fs::path mode_yaml = dir.Write(
        "mode.yaml", "refractive_index: " + index +
                         "\nmodes:\n  - name: fine\n    basis: volume\n    median_radius_um: 0.12\n"
                         "    ln_sigma_g: 0.45\n    r_min_um: 0.05\n    r_max_um: 15\n"
                         "    weight: {relative_volume: 1}\n");
    const ParticleType table = LoadParticleType(table_yaml), mode = LoadParticleType(mode_yaml);
    ASSERT_TRUE(table.modes[0].IsTable());
    EXPECT_NEAR(table.modes[0].MeanVolumeInsideUm3() / mode.modes[0].MeanVolumeInsideUm3(), 1.0, 1e-4);
    QuadratureOptions q;
    q.tolerance = 1e-5;
    const PhaseTables pt = MakePhaseTables(StandardPhaseGrid(), WiscombeTerms(2 * kPi * 15.0 / 0.45));
    for (double wl : {450.0, 650.0}) {
      const std::complex<double> m = mode.modes[0].index.At(wl);
      const MixtureIntegral a = IntegrateMode(table.modes[0], wl, m, &pt, q);
      const MixtureIntegral b = IntegrateMode(mode.modes[0], wl, m, &pt, q);
      ASSERT_TRUE(a.converged && b.converged);
      SCOPED_TRACE(index + " at " + std::to_string(wl) + " nm");
      EXPECT_NEAR(a.cext_m2 / b.cext_m2, 1.0, 1e-4);
      EXPECT_NEAR(a.csca_m2 / b.csca_m2, 1.0, 1e-4);
      EXPECT_NEAR((a.cabs_m2 - b.cabs_m2) / b.cext_m2, 0.0, 1e-4);
      EXPECT_NEAR(a.csca_m2 / a.cext_m2 - b.csca_m2 / b.cext_m2, 0.0, 1e-4);
      EXPECT_NEAR(a.gcsca_m2 / a.csca_m2 - b.gcsca_m2 / b.csca_m2, 0.0, 1e-4);
      std::vector<double> pa = a.dcsca_domega_m2_sr, pb = b.dcsca_domega_m2_sr;
      for (double& v : pa) v /= a.csca_m2;
      for (double& v : pb) v /= b.csca_m2;
      EXPECT_LT(PhaseL1(pt.grid, pa, pb), 1e-4);
    }
  }
}

// A coarse table is not the mode: at AERONET's 22 radii (spacing 0.27 in ln r) a narrow mode
// (the GT7 accumulation sub-mode III, r_V = 1.81 um, ln sigma_g = 0.2) loses its shape and C_ext
// moves by far more than the quadrature tolerance (the previous test's agreement is the fine
// table's, not a comparison that passes anything).
TEST(SizeTable, TwentyTwoBinsOfANarrowModeDifferFromIt) {
  TempDir dir;
  dir.Write("fine.csv", SampledCsv(1.81, 0.2, 0.05, 15.0, 22));
  const ParticleType table = LoadParticleType(dir.Write(
      "t.yaml", "refractive_index: {n: 1.33, k: 1e-8}\nmodes:\n  - name: fine\n    size_table: fine.csv\n"
                "    weight: {relative_volume: 1}\n"));
  const ParticleType mode = LoadParticleType(dir.Write(
      "m.yaml", "refractive_index: {n: 1.33, k: 1e-8}\nmodes:\n  - name: fine\n    basis: volume\n"
                "    median_radius_um: 1.81\n    ln_sigma_g: 0.2\n    r_min_um: 0.05\n    r_max_um: 15\n"
                "    weight: {relative_volume: 1}\n"));
  const MixtureIntegral a = IntegrateMode(table.modes[0], 550.0, {1.33, 1e-8}, nullptr, QuadratureOptions{});
  const MixtureIntegral b = IntegrateMode(mode.modes[0], 550.0, {1.33, 1e-8}, nullptr, QuadratureOptions{});
  EXPECT_GT(std::abs(a.cext_m2 / b.cext_m2 - 1.0), 1e-2);
}

// Moments are exact: a constant dN/d ln r on [r1, r2] has <r^k> = (r2^k - r1^k) / (k ln(r2/r1)).
TEST(SizeTable, MomentsOfAConstantNumberTableAreExact) {
  TempDir dir;
  const fs::path csv = dir.Write("flat.csv", "# source: test\nradius_nm,dN_dlnr_cm3\n100,7\n400,7\n2000,7\n");
  SizeTable t;
  t.file = csv;
  t.Load();
  EXPECT_EQ(t.basis, SizeBasis::kNumber);
  const double r1 = 0.1, r2 = 2.0;
  for (int k : {1, 2, 3, 4}) {
    const double expected = (std::pow(r2, k) - std::pow(r1, k)) / (k * std::log(r2 / r1));
    EXPECT_NEAR(t.MomentUm(k) / expected, 1.0, 1e-13) << k;
  }
  EXPECT_NEAR(t.NumberMoment(0), 7.0 * std::log(r2 / r1), 1e-12);
  EXPECT_EQ(t.NumberDensity(std::log(0.05)), 0.0);
  EXPECT_EQ(t.NumberDensity(std::log(3.0)), 0.0);
  EXPECT_DOUBLE_EQ(t.NumberDensity(std::log(0.2)), 7.0);
  // The series and the closed form of int t e^{at} dt agree where they meet (|a| = 0.5).
  for (double c : {0.4999999, 0.5000001, -0.4999999, -0.5000001}) {
    EXPECT_NEAR(LinearTimesExpIntegral(0.0, 1.0, 0.0, 1.0, c), (std::exp(c) * (c - 1.0) + 1.0) / (c * c), 1e-14);
  }
}

// Bad tables and misused keys are reported with file:line, every problem at once.
TEST(SizeTable, BadTablesAreReportedWithFileAndLine) {
  TempDir dir;
  const std::string yaml = "refractive_index: {n: 1.5}\nmodes:\n  - name: t\n    size_table: bad.csv\n"
                           "    weight: {relative_volume: 1}\n";
  const fs::path csv = dir.Write("bad.csv", "# source: test\nradius_um,dV_dlnr_um3_um2\n0.1,1\n0.1,2\n0.3,-999\n");
  const fs::path y = dir.Write("t.yaml", yaml);
  EXPECT_EQ(LoadErrors(y), csv.string() + ":4: column 'radius_um': radii must increase strictly (0.1 after 0.1)\n" +
                               csv.string() +
                               ":5: column 'dV_dlnr_um3_um2': a density must be a finite number >= 0, got -999 "
                               "(AERONET's fill value: a missing retrieval)\n");
  dir.Write("bad.csv", "# source: test\nradius_um,dV_dlnr_um3_um2,dN_dlnr_cm3\n0.1,1,1\n0.2,1,1\n");
  EXPECT_EQ(LoadErrors(y), csv.string() +
                               ":2: expected exactly one density column, dV_dlnr_<unit> (volume basis) or "
                               "dN_dlnr_<unit> (number basis), e.g. dV_dlnr_um3_um2; found 2 (columns: radius_um, "
                               "dV_dlnr_um3_um2, dN_dlnr_cm3)\n");
  dir.Write("bad.csv", "# source: test\nradius_um,dV_dlnr_um3_um2\n0.1,0\n0.2,0\n");
  EXPECT_EQ(LoadErrors(y), csv.string() + ":2: column 'dV_dlnr_um3_um2': every density is 0\n");
  const fs::path y2 = dir.Write("t2.yaml", "refractive_index: {n: 1.5}\nmodes:\n  - name: t\n    size_table: bad.csv\n"
                                           "    ln_sigma_g: 0.4\n    weight: {relative_volume: 1}\n");
  EXPECT_NE(LoadErrors(y2).find("t2.yaml:5: "), std::string::npos) << LoadErrors(y2);
}

// Points: n linear and k log-linear between them; outside, the end value (nearest) or the end
// interval continued (linear); a linear extension that leaves the valid range is a coverage error.
TEST(SizeTable, RefractiveIndexFromPoints) {
  YamlDocument doc = YamlDocument::Parse(
      "refractive_index:\n  points: {wavelength_nm: [440, 675, 870, 1020], n: [1.50, 1.52, 1.53, 1.54],"
      " k: [0.004, 0.001, 0.001, 0.001]}\n  extrapolation: nearest\nmodes:\n  - name: a\n    basis: volume\n"
      "    median_radius_um: 0.2\n    ln_sigma_g: 0.5\n    r_min_um: 0.05\n    r_max_um: 15\n"
      "    weight: {relative_volume: 1}\n",
      "p.yaml", SKYBAKE_SOURCE_DIR "/particles");
  const ParticleType t = ParseParticleType(doc, "p");
  const RefractiveIndex& ri = t.modes[0].index;
  EXPECT_NEAR(ri.At(557.5).real(), 1.51, 1e-12);
  EXPECT_NEAR(ri.At(557.5).imag(), 0.002, 1e-12);  // the geometric mean of 0.004 and 0.001
  EXPECT_DOUBLE_EQ(ri.At(360.0).real(), 1.50);
  EXPECT_DOUBLE_EQ(ri.At(360.0).imag(), 0.004);
  EXPECT_NO_THROW(CheckWavelengthCoverage(t, 360.0, 830.0));

  RefractiveIndex lin = ri;
  lin.extrapolation = RefractiveIndex::Extrapolation::kLinear;
  EXPECT_NEAR(lin.At(360.0).real(), 1.50 - 0.02 * 80.0 / 235.0, 1e-12);
  EXPECT_NEAR(lin.At(360.0).imag(), 0.004 * std::pow(4.0, 80.0 / 235.0), 1e-12);
  EXPECT_TRUE(lin.Covers(360.0, 830.0));

  // n = 1.10 at 440 nm, 1.05 at 675 nm, continued linearly: 1.017 at 830 nm, below 1 from 1015 nm.
  YamlDocument steep = YamlDocument::Parse(
      "refractive_index:\n  points: {wavelength_nm: [440, 675], n: [1.10, 1.05], k: [0, 0]}\n"
      "  extrapolation: linear\nmodes:\n  - name: a\n    basis: volume\n    median_radius_um: 0.2\n"
      "    ln_sigma_g: 0.5\n    r_min_um: 0.05\n    r_max_um: 15\n    weight: {relative_volume: 1}\n",
      "s.yaml", SKYBAKE_SOURCE_DIR "/particles");
  const ParticleType s = ParseParticleType(steep, "s");
  EXPECT_NEAR(s.modes[0].index.At(830.0).real(), 1.05 - 0.05 * 155.0 / 235.0, 1e-12);
  EXPECT_NO_THROW(CheckWavelengthCoverage(s, 360.0, 830.0));
  try {
    CheckWavelengthCoverage(s, 360.0, 1500.0);
    ADD_FAILURE() << "no coverage error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.diagnostics()[0].ToString(),
              "s.yaml:2: mode 'a': the refractive index covers points at 440-675 nm and their linear extrapolation "
              "while n stays in 1-3 and k in 0-3, the wavelength grid needs 360-1500 nm");
  }
  // Points and a table or constant at once, unequal lengths: errors at the YAML line.
  YamlDocument bad = YamlDocument::Parse(
      "refractive_index:\n  points: {wavelength_nm: [440, 675], n: [1.5], k: [0, 0]}\n  extrapolation: linear\n"
      "modes:\n  - name: a\n    basis: volume\n    median_radius_um: 0.2\n    ln_sigma_g: 0.5\n"
      "    r_min_um: 0.05\n    r_max_um: 15\n    weight: {relative_volume: 1}\n",
      "b.yaml", SKYBAKE_SOURCE_DIR "/particles");
  try {
    ParseParticleType(bad, "b");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.diagnostics()[0].ToString(), "b.yaml:2: key 'refractive_index.points': wavelength_nm, n and k must have the same length (2, 1, 2)");
  }
}
