// Size-distribution integrals: the fast angular sums against the direct amplitude sums, the tiny-
// sigma limit, the refinement criterion against a finer reference, mixtures, Rayleigh limits,
// normalisation and thread independence of whole tables.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "io/yaml.h"
#include "optics/mie_angular.h"
#include "optics/polydisperse.h"
#include "support/threads.h"

namespace fs = std::filesystem;
using namespace skybake;
using namespace skybake::mie;

namespace {

constexpr double kPi = std::numbers::pi;

ParticleType TypeFromText(const std::string& text) {
  YamlDocument doc = YamlDocument::Parse(text, "test.yaml", SKYBAKE_SOURCE_DIR "/particles");
  return ParseParticleType(doc, "test");
}

std::string Mode(const std::string& name, double median_um, double ln_sigma, double rmin, double rmax,
                 const std::string& index = "") {
  return "  - name: " + name + "\n" + (index.empty() ? "" : "    refractive_index: " + index + "\n") +
         "    basis: number\n    median_radius_um: " + FormatExact(median_um) +
         "\n    ln_sigma_g: " + FormatExact(ln_sigma) + "\n    r_min_um: " + FormatExact(rmin) +
         "\n    r_max_um: " + FormatExact(rmax) + "\n    weight: {relative_number: 1}\n";
}

// Exact integral over the sphere of the log-linear interpolant of P times mu (mie_table.h):
// on a segment mu = mu_j - t dmu, P = P_j e^{L t}: int mu P dmu = dmu P_j int_0^1 (mu_j - t dmu) e^{Lt} dt.
double PhaseMoment(const std::vector<double>& mu, const std::vector<double>& p) {
  double total = 0.0;
  for (size_t j = 0; j + 1 < mu.size(); ++j) {
    const double dmu = mu[j] - mu[j + 1], L = std::log(p[j + 1] / p[j]);
    const double i0 = std::abs(L) < 1e-8 ? 1.0 + L / 2.0 : std::expm1(L) / L;
    const double i1 = std::abs(L) < 1e-8 ? 0.5 + L / 3.0 : (std::exp(L) * (L - 1.0) + 1.0) / (L * L);
    total += 2.0 * kPi * dmu * p[j] * (mu[j] * i0 - dmu * i1);
  }
  return total;
}

}  // namespace

// sum_r w_r (|S1|^2 + |S2|^2)/2 through the Gram matrices equals the direct sum of the amplitudes
// (mie_sphere.h Amplitudes, the obviously right reference) at every grid angle. 20 radii cross the
// kernel's batch size; the sizes and indices span the regimes.
TEST(Polydisperse, GramIntensitiesMatchDirectAmplitudeSums) {
  const PhaseGrid grid = StandardPhaseGrid();
  const AngularTables tables(grid, 500);
  for (Complex m : {Complex(1.33, 1e-9), Complex(1.75, 0.44), Complex(10.0, 10.0)}) {
    IntensityAccumulator acc(500);
    std::vector<double> ref(grid.size(), 0.0);
    MieWorkspace ws;
    MieCoefficients c;
    std::vector<Complex> s1, s2;
    for (int r = 0; r < 20; ++r) {
      const double x = 0.05 * std::pow(1.55, r);  // 0.05 .. 200
      const double w = 1.0 + 0.1 * r;
      ComputeCoefficients(x, m, c, ws);
      acc.Add(c, w);
      Amplitudes(c, grid.mu, s1, s2);
      for (size_t j = 0; j < grid.size(); ++j) ref[j] += w * 0.5 * (std::norm(s1[j]) + std::norm(s2[j]));
    }
    std::vector<double> out(grid.size());
    acc.Evaluate(tables, out);
    for (size_t j = 0; j < grid.size(); ++j) {
      ASSERT_NEAR(out[j], ref[j], 1e-9 * ref[j]) << "m = " << m << ", theta = " << grid.theta_rad[j] * 180 / kPi;
    }
  }
}

// A mode with a tiny width reproduces the single sphere at its radius: cross sections, g and the
// phase function P = i / (k^2 C_sca) at every angle. (sigma_g = e^1e-4: the mean of Q over the mode
// differs from Q(r) by O(s^2) = 1e-8 relative.)
TEST(Polydisperse, TinySigmaReproducesTheSingleSphere) {
  const ParticleType t = TypeFromText("refractive_index: {n: 1.5, k: 0.01}\nmodes:\n" + Mode("one", 0.5, 1e-4, 0.1, 2.0));
  const double wl = 550.0, k = 2.0 * kPi / (wl * 1e-9), r = 0.5e-6;
  const PhaseTables pt = MakePhaseTables(StandardPhaseGrid(), 40);
  // The quadrature to 1e-8, below the 1e-6 compared (panels at different levels integrate a
  // Gaussian to O(h^2), not spectrally as one uniform trapezoid would).
  QuadratureOptions o;
  o.tolerance = 1e-8;
  const MixtureIntegral mi = IntegrateMode(t.modes[0], wl, Complex(1.5, 0.01), &pt, o);
  ASSERT_TRUE(mi.converged);
  const MieSphereResult s = MieSphere(k * r, Complex(1.5, 0.01), pt.grid.mu);
  const double area = kPi * r * r;
  EXPECT_NEAR(mi.cext_m2 / (area * s.q.qext), 1.0, 1e-6);
  EXPECT_NEAR(mi.csca_m2 / (area * s.q.qsca), 1.0, 1e-6);
  EXPECT_NEAR(mi.cabs_m2 / (area * s.q.qabs), 1.0, 1e-6);
  EXPECT_NEAR(mi.gcsca_m2 / mi.csca_m2, s.q.g, 1e-6);
  for (size_t j = 0; j < pt.grid.size(); ++j) {
    const double p_sphere = 0.5 * (std::norm(s.s1[j]) + std::norm(s.s2[j])) / (k * k * area * s.q.qsca);
    EXPECT_NEAR(mi.dcsca_domega_m2_sr[j] / mi.csca_m2, p_sphere, 1e-5 * p_sphere) << j;
  }
}

// The refinement criterion: when every integral changed by < 1e-4 between the last two levels,
// the result is within 1e-4 of a reference refined three levels further (8x the radii). Checked on
// a nearly non-absorbing water mode (resonances make this the hard case) and an absorbing one.
TEST(Polydisperse, RefinementConvergesToTheStatedTolerance) {
  const ParticleType t = TypeFromText("modes:\n" + Mode("water", 1.0, 0.4, 0.05, 15.0, "{n: 1.333, k: 2e-9}") +
                                      Mode("soot", 0.05, 0.7, 0.005, 20.0, "{n: 1.75, k: 0.44}"));
  const PhaseTables pt = MakePhaseTables(StandardPhaseGrid(), 300);
  for (const SizeMode& mode : t.modes) {
    SCOPED_TRACE(mode.name);
    const Complex m = mode.index.At(600.0);
    QuadratureOptions o;
    const MixtureIntegral a = IntegrateMode(mode, 600.0, m, &pt, o);
    ASSERT_TRUE(a.converged);
    EXPECT_LT(a.change, 1e-4);
    o.min_levels = a.levels + 3;
    o.tolerance = 0.0;
    o.max_levels = a.levels + 3;
    const MixtureIntegral ref = IntegrateMode(mode, 600.0, m, &pt, o);
    EXPECT_GT(ref.radii, 7 * a.radii);
    EXPECT_NEAR(a.cext_m2 / ref.cext_m2, 1.0, 1e-4);
    EXPECT_NEAR(a.csca_m2 / ref.csca_m2, 1.0, 1e-4);
    EXPECT_NEAR(a.gcsca_m2 / a.csca_m2, ref.gcsca_m2 / ref.csca_m2, 1e-4);
    double l1 = 0.0;
    for (size_t j = 0; j + 1 < pt.grid.size(); ++j) {
      const double dmu = pt.grid.mu[j] - pt.grid.mu[j + 1];
      auto d = [&](size_t i) { return std::abs(a.dcsca_domega_m2_sr[i] / a.csca_m2 - ref.dcsca_domega_m2_sr[i] / ref.csca_m2); };
      l1 += kPi * dmu * (d(j) + d(j + 1));
    }
    EXPECT_LT(l1, 1e-4);
    // A stricter tolerance takes more radii.
    QuadratureOptions strict;
    strict.tolerance = 1e-5;
    EXPECT_GT(IntegrateMode(mode, 600.0, m, &pt, strict).radii, a.radii);
  }
}

// The panels' levels follow the integrand's weight: on the water cloud at 830 nm (x up to 303)
// the adaptive quadrature takes under half the radii of every panel at its finest panel's level,
// and agrees with that uniform one within the tolerance.
TEST(Polydisperse, AdaptivePanelsSpendRadiiWhereTheWeightIs) {
  const ParticleType t = LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "water_cloud.yaml");
  const PhaseTables pt = MakePhaseTables(StandardPhaseGrid(), WiscombeTerms(310.0));
  const Complex m = t.modes[0].index.At(830.0);
  const MixtureIntegral a = IntegrateMode(t.modes[0], 830.0, m, &pt, QuadratureOptions{});
  ASSERT_TRUE(a.converged);
  EXPECT_LT(a.change, 1e-4);
  EXPECT_LT(a.panel_change_sum, 3e-4);
  QuadratureOptions uniform;
  uniform.min_levels = a.levels;
  uniform.max_levels = a.levels;
  uniform.tolerance = 0.0;
  const MixtureIntegral u = IntegrateMode(t.modes[0], 830.0, m, &pt, uniform);
  EXPECT_LT(2 * a.radii, u.radii);
  EXPECT_NEAR(a.cext_m2 / u.cext_m2, 1.0, 1e-4);
  EXPECT_NEAR(a.gcsca_m2 / a.csca_m2, u.gcsca_m2 / u.csca_m2, 1e-4);
  double l1 = 0.0;
  for (size_t j = 0; j + 1 < pt.grid.size(); ++j) {
    const double dmu = pt.grid.mu[j] - pt.grid.mu[j + 1];
    auto d = [&](size_t i) { return std::abs(a.dcsca_domega_m2_sr[i] / a.csca_m2 - u.dcsca_domega_m2_sr[i] / u.csca_m2); };
    l1 += kPi * dmu * (d(j) + d(j + 1));
  }
  EXPECT_LT(l1, 1e-4);
  std::printf("water cloud at 830 nm: %d radii adaptive (finest level %d), %d uniform; P differs by %.2g (L1)\n",
              a.radii, a.levels, u.radii, l1);
}

// Modes with different indices integrate on separate grids; the mixture is the fraction-weighted
// sum of its modes (to the quadrature tolerance: the grids differ).
TEST(Polydisperse, MixtureIsTheWeightedSumOfItsModes) {
  const ParticleType t = TypeFromText("modes:\n" + Mode("a", 0.1, 0.6, 0.005, 10.0, "{n: 1.45, k: 0.003}") +
                                      Mode("b", 0.8, 0.3, 0.05, 10.0, "{n: 1.53, k: 0.008}"));
  const PhaseTables pt = MakePhaseTables(StandardPhaseGrid(), 200);
  const double wl = 500.0, f0 = 0.9, f1 = 0.1;
  const MixturePart parts[] = {{&t.modes[0], f0, t.modes[0].index.At(wl)}, {&t.modes[1], f1, t.modes[1].index.At(wl)}};
  const MixtureIntegral mix = IntegrateMixture(parts, wl, &pt, QuadratureOptions{});
  ASSERT_EQ(mix.group_radii.size(), 2u);
  const MixtureIntegral a = IntegrateMode(t.modes[0], wl, parts[0].m, &pt, QuadratureOptions{});
  const MixtureIntegral b = IntegrateMode(t.modes[1], wl, parts[1].m, &pt, QuadratureOptions{});
  EXPECT_NEAR(mix.cext_m2 / (f0 * a.cext_m2 + f1 * b.cext_m2), 1.0, 2e-4);
  EXPECT_NEAR(mix.cabs_m2 / (f0 * a.cabs_m2 + f1 * b.cabs_m2), 1.0, 2e-4);
  EXPECT_NEAR(mix.gcsca_m2 / (f0 * a.gcsca_m2 + f1 * b.gcsca_m2), 1.0, 2e-4);
}

// Tiny particles scatter as Rayleigh: C_sca ~ lambda^-4 (constant m), P = 3/(16 pi) (1 + cos^2),
// g ~ 0 (to O(x^2): the mode's r^6-weighted sizes reach x ~ 0.3 at 400 nm).
TEST(Polydisperse, SmallParticlesApproachRayleigh) {
  const ParticleType t = TypeFromText("refractive_index: {n: 1.5, k: 0}\nmodes:\n" + Mode("tiny", 0.002, 0.3, 0.0005, 0.02));
  const std::vector<double> wl{400.0, 800.0};
  MieBuildOptions o;
  o.fits = false;
  const MieBuild b = BuildMieTable(t, wl, o);
  EXPECT_NEAR(std::log(b.table.csca_m2[0] / b.table.csca_m2[1]) / std::log(2.0), 4.0, 1e-3);
  EXPECT_LT(std::abs(b.table.g[0]), 1e-3);
  const MieTable& tb = b.table;
  EXPECT_NEAR(tb.EvalPhase(0, 1.0) / tb.EvalPhase(0, 0.0), 2.0, 5e-3);
  EXPECT_NEAR(tb.EvalPhase(0, 1.0) / (3.0 / (8.0 * kPi)), 1.0, 5e-3);
  EXPECT_NEAR(tb.EvalPhase(1, 1.0) / (3.0 / (8.0 * kPi)), 1.0, 2e-3);  // 800 nm: x halves, closer
}

// The table of the GT7 case study at three wavelengths: the analytic phase function integrates to 1
// within 1e-4 on the grid; g from the Mie series equals int P cos dOmega; C_ext = C_sca + C_abs;
// 0 <= albedo <= 1; the wavelength dependence of the fine mode (blue) is the talk's point.
TEST(Polydisperse, Gt7TableLaws) {
  const ParticleType t = LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "gt7_case_study.yaml");
  const std::vector<double> wl{360.0, 550.0, 830.0};
  const MieBuild b = BuildMieTable(t, wl, MieBuildOptions{});
  const MieTable& tb = b.table;
  for (size_t w = 0; w < wl.size(); ++w) {
    SCOPED_TRACE(wl[w]);
    EXPECT_LT(std::abs(tb.phase_norm_error[w]), 1e-4);
    EXPECT_NEAR(IntegratePhase(tb.mu, tb.phase[w]), 1.0, 1e-12);
    EXPECT_NEAR(PhaseMoment(tb.mu, tb.phase[w]), tb.g[w], 2e-4);
    EXPECT_NEAR(tb.cext_m2[w], tb.csca_m2[w] + tb.cabs_m2[w], 1e-12 * tb.cext_m2[w]);
    EXPECT_GT(tb.ssa[w], 0.0);
    EXPECT_LE(tb.ssa[w], 1.0);
    EXPECT_TRUE(b.integrals[w].converged);
  }
}

// The sharpest forward peak of the shipped aerosol types, the GT7 coarse mode at 360 nm: on the
// table's angle grid its phase function still integrates to 1 within 1e-4 (phase_grid.h).
TEST(Polydisperse, AngleGridResolvesTheCoarseModePeak) {
  const ParticleType t = SelectMode(LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "gt7_case_study.yaml"), "coarse");
  MieBuildOptions o;
  o.fits = false;
  const MieBuild b = BuildMieTable(t, std::vector<double>{360.0}, o);
  EXPECT_GE(b.table.theta_rad.size(), 1800u);
  EXPECT_LT(std::abs(b.table.phase_norm_error[0]), 1e-4);
  EXPECT_NEAR(PhaseMoment(b.table.mu, b.table.phase[0]), b.table.g[0], 2e-4);
}

// Same bytes at any thread count: each wavelength is computed alone, in a fixed order.
TEST(Polydisperse, TablesDoNotDependOnTheThreadCount) {
  const ParticleType t = LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "continental.yaml");
  const std::vector<double> wl{450.0, 650.0};
  const MieBuild one = test::WithThreads(1, [&] { return BuildMieTable(t, wl, MieBuildOptions{}); });
  const MieBuild two = test::WithThreads(2, [&] { return BuildMieTable(t, wl, MieBuildOptions{}); });
  EXPECT_EQ(one.table.cext_m2, two.table.cext_m2);
  EXPECT_EQ(one.table.g, two.table.g);
  EXPECT_EQ(one.table.phase, two.table.phase);
  EXPECT_EQ(one.table.fits[1].dhg_g1, two.table.fits[1].dhg_g1);
}
