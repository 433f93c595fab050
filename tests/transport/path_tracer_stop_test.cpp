// The path tracer's adaptive stop under heavy tails (transport/path_tracer.h, stderr_reliability;
// docs/sky-render.md "Honest error bars"): the reported standard error covers the spread of
// independent estimates of a thin, strongly forward-scattering cloud as a Gaussian error bar
// should, and the stop on the sample variance alone does not.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "transport/path_tracer.h"
#include "transport/random.h"
#include "transport/running_moments.h"

using namespace skybake;

namespace {
constexpr double kPi = std::numbers::pi;

// A thin cloud: a homogeneous layer from the ground to 1 km of vertical optical depth 1, half of
// it scattering by Henyey-Greenstein g = 0.99 (a droplet's diffraction peak: P(0) = 1592 sr^-1)
// and half by g = 0.7 (its broad part), no absorption, over a ground of albedo 0.1, one
// wavelength with a unit sun.
AtmosphereModel ThinCloud(double g_peak) {
  AtmosphereModel m;
  m.bottom_radius_m = 6371e3;
  m.top_radius_m = m.bottom_radius_m + 1000.0;
  m.altitude_m = {0.0, 1000.0};
  m.wavelength_nm = {550.0};
  for (double g : {g_peak, 0.7}) {
    MediumComponent c;
    c.name = g > 0.9 ? "peak" : "broad";
    c.phase = std::make_shared<HenyeyGreensteinPhase>(std::vector<double>{g});
    c.scattering = {5e-4, 5e-4};  // m^-1: tau 0.5 over 1 km
    c.absorption = {0.0, 0.0};
    m.components.push_back(c);
  }
  m.ground_albedo = {0.1};
  m.sun.irradiance = {1.0};
  m.sun.angular_radius_rad = 1e-4;
  m.Finalize();
  return m;
}

struct Coverage {
  double one_sigma = 0, two_sigma = 0;
};

// Fraction of `seeds` adaptive estimates per view direction within 1 and 2 reported standard
// errors of a fixed-count reference (no stopping rule, so no stopping bias).
Coverage Measure(double g_peak, double stderr_reliability, double peak_events, int seeds) {
  const AtmosphereModel m = ThinCloud(g_peak);
  const std::vector<std::array<double, 3>> w(1, {1.0, 1.0, 1.0});
  const glm::dvec3 pos(0, 0, m.bottom_radius_m + 1.0), sun = DirectionFromAngles(50 * kPi / 180, 0);
  const glm::dvec3 views[] = {DirectionFromAngles(0.0, 0.0), DirectionFromAngles(60 * kPi / 180, kPi),
                              DirectionFromAngles(80 * kPi / 180, kPi / 2)};
  PathTracerSettings ref_settings;
  ref_settings.wavelengths_per_path = 1;
  ref_settings.seed = 7777;
  const PathTracer ref(m, w, ref_settings);
  int in1 = 0, in2 = 0, total = 0;
  for (size_t v = 0; v < std::size(views); ++v) {
    std::vector<double> truth, truth_se;
    ref.SpectralRadiance(pos, views[v], sun, {0}, 300000, 1000 + v, &truth, &truth_se);
    for (int s = 0; s < seeds; ++s) {
      PathTracerSettings ps = ref_settings;
      ps.seed = 100 + static_cast<uint64_t>(s);
      ps.target_relative_error = 0.1;
      ps.stderr_reliability = stderr_reliability;
      ps.rare_peak_events = peak_events;
      const PathTracer pt(m, w, ps);
      const ColorEstimate e = pt.Radiance(pos, views[v], sun, v);
      const double z = (e.xyz[1] - truth[0]) / std::hypot(e.xyz_stderr[1], truth_se[0]);
      in1 += std::abs(z) <= 1.0;
      in2 += std::abs(z) <= 2.0;
      ++total;
    }
  }
  return {static_cast<double>(in1) / total, static_cast<double>(in2) / total};
}
}  // namespace

// 90 estimates (3 view directions x 30 seeds) at 10 % target error under a thin cloud (g = 0.95
// peak: P(0) = 62 sr^-1, so the cloud estimators act). With the default stop their reported
// 1 sigma interval holds the reference in 68 % +- 10 % of them and the 2 sigma interval in at
// least 88 % (a Gaussian error bar: 68.3 % and 95.4 %; the binomial spread of 90 draws is +- 5 %
// and +- 2 %, and the estimates' remaining skew - a heavy right tail leaves most of them low -
// costs a few per cent at 2 sigma; measured 63.3 / 92.2 %). The stop on the sample variance
// alone (stderr_reliability 0, rare_peak_events 0) covers visibly less at 2 sigma (measured
// 56.7 / 84.4 %): that is what the two conditions are for.
TEST(PathTracerStop, ErrorBarsCoverTheSpreadUnderAThinCloud) {
  const Coverage plain = Measure(0.95, 0.0, 0.0, 30);
  const PathTracerSettings defaults;
  const Coverage honest = Measure(0.95, defaults.stderr_reliability, defaults.rare_peak_events, 30);
  std::printf("coverage of 1 and 2 sigma: plain %.3f %.3f, default stop %.3f %.3f\n", plain.one_sigma, plain.two_sigma,
              honest.one_sigma, honest.two_sigma);
  EXPECT_GE(honest.one_sigma, 0.58);
  EXPECT_LE(honest.one_sigma, 0.78);
  EXPECT_GE(honest.two_sigma, 0.88);
  EXPECT_LT(plain.two_sigma, honest.two_sigma - 0.04);
}

// The one-pass moments against the two-pass sums of the same samples, and the reliability of the
// standard error against its closed forms: a Gaussian-like sample (kappa ~ 3) at n = 200 knows its
// standard error to sqrt(2/200)/2 = 5 %; a sample with one outlier does not.
TEST(PathTracerStop, RunningMomentsMatchTheTwoPassSums) {
  std::vector<double> x;
  Pcg32 rng(5, 0, 0);
  for (int i = 0; i < 200; ++i) x.push_back(10.0 + rng.Uniform() + rng.Uniform() + rng.Uniform() - 1.5);
  RunningMoments r;
  for (double v : x) r.Add(v);
  double mean = 0;
  for (double v : x) mean += v / static_cast<double>(x.size());
  double m2 = 0, m3 = 0, m4 = 0;
  for (double v : x) {
    m2 += std::pow(v - mean, 2);
    m3 += std::pow(v - mean, 3);
    m4 += std::pow(v - mean, 4);
  }
  EXPECT_NEAR(r.mean, mean, 1e-12 * mean);
  EXPECT_NEAR(r.m2, m2, 1e-10 * m2);
  EXPECT_NEAR(r.m3, m3, 1e-9 * m2 * std::sqrt(m2));
  EXPECT_NEAR(r.m4, m4, 1e-10 * m4);
  const double n = 200, kappa = n * m4 / (m2 * m2);
  EXPECT_NEAR(r.StdErrRelativeUncertainty(), 0.5 * std::sqrt((kappa - (n - 3) / (n - 1)) / n), 1e-12);
  // The sum of three uniforms has kurtosis 2.6 (3 - 6/15): about 5 %.
  EXPECT_GT(r.StdErrRelativeUncertainty(), 0.03);
  EXPECT_LT(r.StdErrRelativeUncertainty(), 0.06);
  r.Add(1000.0);  // one sample 100x the mean dominates the variance: its estimate is unreliable
  EXPECT_GT(r.StdErrRelativeUncertainty(), 0.4);
  RunningMoments constant;
  for (int i = 0; i < 10; ++i) constant.Add(2.0);
  EXPECT_EQ(constant.StdErrRelativeUncertainty(), 0.0);
  EXPECT_EQ(constant.StdErr(), 0.0);
}

// The minimum path count follows the sharpest phase peak: rare_peak_events x 4 pi P_max paths
// (HG g = 0.95: P(1) = (1 - g^2) / (4 pi (1 - g)^3), so 4 pi P_max = 780 and 3 events 2340 paths)
// without the sun-peak guide; with it at most guided_peak_paths (1024); without the condition it
// is min_paths.
TEST(PathTracerStop, MinimumPathsFollowThePhasePeak) {
  const std::vector<std::array<double, 3>> w(1, {1.0, 1.0, 1.0});
  const AtmosphereModel cloud = ThinCloud(0.95);
  PathTracerSettings unguided;
  unguided.sun_peak_guide = 0.0;
  EXPECT_NEAR(static_cast<double>(PathTracer(cloud, w, unguided).MinPaths()), 3.0 * (1 - 0.95 * 0.95) / std::pow(0.05, 3),
              1.0);  // ceil of a rounded 2340
  EXPECT_EQ(PathTracer(cloud, w, PathTracerSettings{}).MinPaths(), 1024u);
  EXPECT_NEAR(static_cast<double>(PathTracer(ThinCloud(0.8), w, PathTracerSettings{}).MinPaths()),
              3.0 * (1 - 0.8 * 0.8) / std::pow(0.2, 3), 1.0);  // 135 paths: below the guided cap
  PathTracerSettings off;
  off.rare_peak_events = 0.0;
  EXPECT_EQ(PathTracer(cloud, w, off).MinPaths(), off.min_paths);
}
