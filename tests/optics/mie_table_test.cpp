// The Mie table API the renderers use: EvalPhase / SamplePhaseCosTheta agree (chi-square test of
// the sampler against integrals of EvalPhase), the EXR round trip, wavelength interpolation and
// the reader's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "io/error.h"
#include "io/exr.h"
#include "io/yaml.h"
#include "optics/mie_table.h"
#include "optics/polydisperse.h"

namespace fs = std::filesystem;
using namespace skybake;
using namespace skybake::mie;

namespace {

constexpr double kPi = std::numbers::pi;

// The GT7 coarse mode (the sharpest forward peak of the shipped types) at two wavelengths.
const MieTable& CoarseTable() {
  static const MieTable t = [] {
    const ParticleType type = SelectMode(
        LoadParticleType(fs::path(SKYBAKE_SOURCE_DIR) / "particles" / "gt7_case_study.yaml"), "coarse");
    return BuildMieTable(type, std::vector<double>{450.0, 650.0}, MieBuildOptions{}).table;
  }();
  return t;
}

// Integral of EvalPhase over [mu_lo, mu_hi] (x 2 pi) by composite Simpson with many sub-steps per
// grid interval - independent of the CDF code it checks.
double IntegrateEval(const MieTable& t, size_t wl, double mu_lo, double mu_hi) {
  double total = 0.0;
  // Split at the grid nodes inside, so each piece is one smooth segment of the interpolant.
  std::vector<double> cuts{mu_lo};
  for (double m : t.mu) {
    if (m > mu_lo && m < mu_hi) cuts.push_back(m);
  }
  cuts.push_back(mu_hi);
  std::sort(cuts.begin(), cuts.end());
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    const int n = 16;
    double s = 0.0;
    for (int k = 0; k <= n; ++k) {
      const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      s += w * t.EvalPhase(wl, a + (b - a) * k / n);
    }
    total += s * (b - a) / (3.0 * n);
  }
  return 2.0 * kPi * total;
}

}  // namespace

// Chi-square test (pbrt-v4 style): 1e6 samples of cos(theta) from SamplePhaseCosTheta in 60 bins
// (log-spaced in theta near the forward peak, uniform elsewhere); expected counts from integrals of
// EvalPhase. With 59 degrees of freedom, chi^2 > 112 has probability 3e-5 for a correct sampler.
TEST(MieTable, SamplingMatchesEvalPhaseChiSquare) {
  const MieTable& t = CoarseTable();
  std::vector<double> edges_deg{0.0};
  for (int i = 0; i <= 30; ++i) edges_deg.push_back(0.05 * std::pow(200.0, i / 30.0));  // 0.05 .. 10 deg
  for (int i = 1; i <= 29; ++i) edges_deg.push_back(10.0 + 170.0 * i / 29.0);
  const size_t bins = edges_deg.size() - 1;
  ASSERT_EQ(bins, 60u);
  for (size_t wl = 0; wl < t.wavelengths(); ++wl) {
    std::vector<double> expected(bins);
    double total = 0.0;
    for (size_t b = 0; b < bins; ++b) {
      expected[b] = IntegrateEval(t, wl, std::cos(edges_deg[b + 1] * kPi / 180.0), std::cos(edges_deg[b] * kPi / 180.0));
      total += expected[b];
    }
    EXPECT_NEAR(total, 1.0, 1e-9);  // EvalPhase integrates to 1
    const int n = 1000000;
    std::mt19937_64 rng(12345 + wl);
    std::vector<int> counts(bins, 0);
    for (int i = 0; i < n; ++i) {
      const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
      const double mu = t.SamplePhaseCosTheta(wl, u);
      const double deg = std::acos(std::clamp(mu, -1.0, 1.0)) * 180.0 / kPi;
      const size_t b = std::min<size_t>(bins - 1, std::upper_bound(edges_deg.begin(), edges_deg.end(), deg) - edges_deg.begin() - 1);
      ++counts[b];
    }
    double chi2 = 0.0;
    for (size_t b = 0; b < bins; ++b) {
      const double e = expected[b] * n;
      ASSERT_GT(e, 5.0) << "bin " << b;  // chi-square needs populated bins
      chi2 += (counts[b] - e) * (counts[b] - e) / e;
    }
    EXPECT_LT(chi2, 112.0) << "wavelength " << t.wavelength_nm[wl];
  }
}

// Inverse-CDF consistency on every segment: CDF(SamplePhaseCosTheta(u)) = u, using the integral of
// EvalPhase from mu to 1.
TEST(MieTable, SampleInvertsTheCdfOfEvalPhase) {
  const MieTable& t = CoarseTable();
  for (double u : {1e-7, 0.01, 0.2, 0.5, 0.77, 0.95, 0.999, 0.9999999}) {
    const double mu = t.SamplePhaseCosTheta(0, u);
    EXPECT_NEAR(IntegrateEval(t, 0, mu, 1.0), u, 1e-9) << u;
  }
  EXPECT_EQ(t.SamplePhaseCosTheta(0, 0.0), 1.0);
  EXPECT_NEAR(t.SamplePhaseCosTheta(0, 1.0 - 1e-17), -1.0, 1e-9);
}

// Write -> read: every quantity comes back to float32 rounding, the phase functions integrate to 1
// and the CDF rebuilt in double ends at 1.
TEST(MieTable, ExrRoundTrip) {
  const MieTable& t = CoarseTable();
  const fs::path p = fs::temp_directory_path() / ("skybake_mie_roundtrip_" + std::to_string(::getpid()) + ".exr");
  Provenance prov;
  prov.tool = "test";
  prov.parameters = "test: 1\n";
  WriteMieTable(p, t, prov);
  const MieTable r = ReadMieTable(p);
  fs::remove(p);
  ASSERT_EQ(r.wavelength_nm, t.wavelength_nm);
  ASSERT_EQ(r.theta_rad, t.theta_rad);
  EXPECT_EQ(r.particle, "gt7_case_study");
  EXPECT_NEAR(r.mean_particle_volume_m3, t.mean_particle_volume_m3, 0.0);
  for (size_t w = 0; w < t.wavelengths(); ++w) {
    EXPECT_NEAR(r.cext_m2[w], t.cext_m2[w], 1e-7 * t.cext_m2[w]);
    EXPECT_NEAR(r.ssa[w], t.ssa[w], 1e-7);
    EXPECT_NEAR(r.g[w], t.g[w], 1e-7);
    EXPECT_NEAR(r.fits[w].dhg_g1, t.fits[w].dhg_g1, 1e-7);
    EXPECT_NEAR(IntegratePhase(r.mu, r.phase[w]), 1.0, 1e-12);
    EXPECT_EQ(r.cdf[w].front(), 0.0);
    EXPECT_EQ(r.cdf[w].back(), 1.0);
    for (size_t j = 0; j < t.theta_rad.size(); ++j) {
      ASSERT_NEAR(r.phase[w][j], t.phase[w][j], 2e-7 * t.phase[w][j]);
      ASSERT_LE(r.cdf[w][j], r.cdf[w][std::min(j + 1, t.theta_rad.size() - 1)]);
    }
  }
}

// Linear interpolation in wavelength; the blended phase function and its mixture sampling.
TEST(MieTable, WavelengthInterpolationIsLinear) {
  const MieTable& t = CoarseTable();
  EXPECT_NEAR(t.Interpolate(t.cext_m2, 550.0), 0.5 * (t.cext_m2[0] + t.cext_m2[1]), 1e-15 * t.cext_m2[0]);
  EXPECT_NEAR(t.EvalPhaseAt(500.0, 0.3), 0.75 * t.EvalPhase(0, 0.3) + 0.25 * t.EvalPhase(1, 0.3), 1e-15);
  EXPECT_EQ(t.SamplePhaseCosThetaAt(500.0, 0.1, 0.4), t.SamplePhaseCosTheta(1, 0.4));  // u_pick < t = 0.25
  EXPECT_EQ(t.SamplePhaseCosThetaAt(500.0, 0.3, 0.4), t.SamplePhaseCosTheta(0, 0.4));
  EXPECT_THROW(t.BracketWavelength(440.0), InternalError);
}

TEST(MieTable, ReaderRejectsOtherFiles) {
  const fs::path p = fs::temp_directory_path() / ("skybake_mie_bad_" + std::to_string(::getpid()) + ".exr");
  ExrTable table;
  table.axes = {ExrAxis{"altitude", "m", "test", {0.0, 1.0}}};
  table.channels = {"x"};
  table.channel_units = {"1"};
  table.values = {1.0f, 2.0f};
  WriteExr(p, TableToImage(table));
  try {
    ReadMieTable(p);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ": no part named 'spectral'");
  }
  fs::remove(p);
  std::ofstream(p) << "not an exr";
  EXPECT_THROW(ReadMieTable(p), InputError);
  fs::remove(p);
}
