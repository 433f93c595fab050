// The `orders` method (transport/method_orders.h, Bruneton & Neyret 2008 successive orders on
// tables) against the exact single scattering of `single`, against the converged path tracer in
// the clear and hazed atmospheres from daylight to twilight (measured errors, honest bounds:
// docs/sky-methods.md "orders"), and for determinism at any thread count.
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>

#include "io/error.h"
#include "method_scenes.h"
#include "transport/method_orders.h"
#include "transport/view_segment.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

std::vector<ColorEstimate> PathY(const TestScene& sc, double sun_zenith_deg, const std::vector<std::array<double, 3>>& dirs,
                                 double target) {
  PathTracerSettings ps;
  ps.target_relative_error = target;
  ps.min_paths = 1024;
  PathTracer pt(sc.model, sc.weights, ps);
  std::vector<ColorEstimate> out(dirs.size());
  const glm::dvec3 x(0, 0, sc.model.bottom_radius_m + 1.0);
  tbb::parallel_for(size_t{0}, dirs.size(), [&](size_t d) {
    out[d] = pt.Radiance(x, glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]), DirectionFromAngles(sun_zenith_deg * kDeg, 0), 300 + d);
  });
  return out;
}

// The 10 nm grid (41 wavelengths) of the tests of `high` against the target: on the 20 nm
// test grid two daylight directions come out ~1 % off where finer grids agree.
SceneOptions TenNmGrid() {
  SceneOptions so;
  so.step_nm = 10.0;
  return so;
}

std::unique_ptr<SkyMethod> HighOrders(const TestScene& sc) {
  SkyMethodOptions o;
  o.quality = Quality::kHigh;
  return MakeSkyMethod("orders", sc.model, o, {});
}

}  // namespace

// With no multiple-scattering orders (max_orders 1) `orders` is its exact single scattering plus
// the ground's reflection of the direct sun. Against the path tracer's first order (max_order 1,
// 0.5 % references) on the horizon band with the sun 10 deg high, where the sun's transmittance
// changes e-fold over a few hundred metres of altitude (the sun table's radius nodes follow the
// optical depth and it blends the transmittance's logarithm): measured -0.1 to +0.4 % (hazed, 10 nm
// grid), bound 1.5 %. Against `single` (a different march:
// altitude ladder, its own transmittance table): <= 0.5 % at sun 30 deg; at sun 80 deg `single`
// medium is 2.4-3.6 % above both on the horizon band (measured), so that bound is 4 %.
TEST(MethodOrders, FirstOrderIsTheSingleScattering) {
  const TestScene sc = LoadTestScene("hazed");
  SkyMethodOptions o;
  o.quality = Quality::kMedium;
  o.orders = 1;
  std::unique_ptr<SkyMethod> orders = MakeSkyMethod("orders", sc.model, o, {});
  std::unique_ptr<SkyMethod> single = MakeSkyMethod("single", sc.model, o, {});
  for (const auto& [sza, bound] : {std::pair{30.0, 0.01}, std::pair{80.0, 0.04}}) {
    const std::vector<double> a = MethodY(sc, *orders, sza, SkyDirs()), b = MethodY(sc, *single, sza, SkyDirs());
    for (size_t d = 0; d < a.size(); ++d) {
      std::printf("orders / single, sun %.0f, dir %zu: %+.2f %%\n", sza, d, 100.0 * (a[d] / b[d] - 1.0));
      EXPECT_NEAR(a[d] / b[d], 1.0, bound) << "sun " << sza << " dir " << d;
    }
  }
  const std::vector<std::array<double, 3>> horizon = {Dir(88, 10), Dir(88, 90), Dir(88, 180)};
  PathTracerSettings ps;
  ps.target_relative_error = 0.005;
  ps.min_paths = 1024;
  ps.max_order = 1;
  ps.max_paths = uint64_t{1} << 22;
  PathTracer pt(sc.model, sc.weights, ps);
  const std::vector<double> y = MethodY(sc, *orders, 80.0, horizon);
  for (size_t d = 0; d < horizon.size(); ++d) {
    const ColorEstimate e = pt.Radiance(glm::dvec3(0, 0, sc.model.bottom_radius_m + 1.0),
                                        glm::dvec3(horizon[d][0], horizon[d][1], horizon[d][2]), DirectionFromAngles(80.0 * kDeg, 0), 900 + d);
    std::printf("orders / path, first order, sun 80, 88 deg, dir %zu: %+.2f %% (path +- %.2f %%)\n", d,
                100.0 * (y[d] / e.xyz[1] - 1.0), 100.0 * e.xyz_stderr[1] / e.xyz[1]);
    EXPECT_NEAR(y[d] / e.xyz[1], 1.0, 0.015) << "dir " << d;
  }
}

// All orders against the path tracer (all orders; 1.5 % standard error per direction, 2 % at
// sun 90 deg), clear (aerosol tau_550 0.1) and hazed (0.5), on the 21-wavelength test grid,
// medium tables (5 deg truncation, exponential step integration, view nodes in angle, tail per
// settled element, log-linear twilight sources in the build, the azimuth blend even about the
// sun's plane). Measured (RMS / max over the 10 directions, noise included) at sun 30 / 70 / 85 /
// 90 deg:
//   clear: 1.6 / 3.1, 2.2 / 4.0, 1.4 / 2.2, 2.8 / 4.6 %
//   hazed: 1.6 / 2.8, 2.3 / 4.3, 3.1 / 5.8, 3.2 / 7.2 % (noise-corrected 0.7 / 1.7 / 2.7 / 2.5 %)
// With this reference's noise (1.5 %) the clear rows are mostly noise: against 1 % references on
// 35 directions and 48 wavelengths the noise-corrected RMS is 0.5 / 1.0 / 1.2 / 2.1 % (clear) and
// 0.9 / 2.9 / 2.4 / 1.5 % (hazed) at sun 30 / 70 / 85 / 90 deg (docs/sky-methods.md "orders").
// Twilight, sun 94 deg (elevation -4, the issue's -10...0 deg range: target RMS 3 %),
// 3 % references (twilight paths are expensive): clear 4.6 / 7.1 % (noise-corrected 3.4 %),
// hazed 5.6 / 14.1 % (4.7 %; the max at 89.5 deg, 60 deg from the sun), orders brighter in 8 of
// 10 directions; the chart's 91 directions with 2 % references give clear 1.7 % at -4 deg.
// The bounds are those figures plus the reference's noise. The target (RMS 0.5 %, max
// 2 %) is NOT met; what remains is the forward peak (truncation cone and kernel resolution:
// docs/sky-methods.md "orders").
struct OrdersCase {
  double sza, target, max_rms, max_abs;
};

TEST(MethodOrders, AgainstThePathTracerFromDaylightToTwilight) {
  const std::pair<const char*, std::vector<OrdersCase>> sets[] = {
      {"clear", {{30.0, 0.015, 0.03, 0.05}, {70.0, 0.015, 0.03, 0.06}, {85.0, 0.015, 0.03, 0.07}, {90.0, 0.02, 0.045, 0.08}, {94.0, 0.03, 0.06, 0.10}}},
      {"hazed", {{30.0, 0.015, 0.03, 0.05}, {70.0, 0.015, 0.04, 0.07}, {85.0, 0.015, 0.045, 0.08}, {90.0, 0.02, 0.05, 0.09}, {94.0, 0.03, 0.07, 0.18}}}};
  for (const auto& [atm, cases] : sets) {
    const TestScene sc = LoadTestScene(atm);
    SkyMethodOptions o;
    o.quality = Quality::kMedium;
    std::unique_ptr<SkyMethod> orders = MakeSkyMethod("orders", sc.model, o, {});
    for (const OrdersCase& c : cases) {
      const std::vector<ColorEstimate> ref = PathY(sc, c.sza, SkyDirs(), c.target);
      const std::vector<double> y = MethodY(sc, *orders, c.sza, SkyDirs());
      // worst: the largest difference beyond 2 of the reference's own standard errors (a
      // reference that meets a rare bright path reports the error it has: sun 90 deg, towards
      // the sun, it reaches max_paths at +-12 %; docs/sky-render.md "Honest error bars").
      double ss = 0.0, noise = 0.0, worst = 0.0;
      for (size_t d = 0; d < y.size(); ++d) {
        const double e = y[d] / ref[d].xyz[1] - 1.0, s = ref[d].xyz_stderr[1] / ref[d].xyz[1];
        ss += e * e;
        noise += s * s;
        worst = std::max(worst, std::abs(e) - 2.0 * s);
        EXPECT_TRUE(std::isfinite(y[d]) && y[d] > 0.0) << atm << " sun " << c.sza << " dir " << d;
      }
      const double rms = std::sqrt(ss / static_cast<double>(y.size()));
      const double rms_corrected = std::sqrt(std::max(0.0, ss - noise) / static_cast<double>(y.size()));
      std::printf("orders vs path, %s sun %.0f deg: RMS %.2f %% (noise-corrected %.2f %%), max %.2f %%\n", atm, c.sza,
                  100.0 * rms, 100.0 * rms_corrected, 100.0 * worst);
      EXPECT_LT(rms_corrected, c.max_rms) << atm << " sun " << c.sza;
      EXPECT_LT(worst, c.max_abs) << atm << " sun " << c.sza;
    }
  }
}

// `high` against the path tracer at the daylight target (RMS <= 0.5 %, max <= 2 % outside
// the aureole) on the hazed sky with the sun 30 and 70 deg from the zenith: ten directions
// (SkyDirs), 0.3 % references, a 10 nm grid (41 wavelengths). Measured here (cones per component,
// 192 sun-table radius nodes, 36 azimuths, the sun nodes 1 deg apart from 80 deg, the two-change
// stopping rule): noise-corrected RMS 0.42 / 0.25 %, max 0.93 / 0.94 % at sun 30 / 70 deg.
// On the 20 nm test grid the same code gives 0.67 / 0.42 % (+1.0 and +1.4 % at 40 deg across and
// 60 deg away from the sun at sun 30 deg, where the 10 nm grid and the pipeline's 48-wavelength
// grid give +0.4 to +1.0 %), so this test uses the finer grid. On the pipeline's grid with 35
// directions: 0.19 / 0.29 % RMS, 1.07 / 1.10 % max (docs/sky-methods.md "Measured accuracy"). The
// RMS bound is the target plus 0.1 %; with the sun at 85 deg high is 0.45 % RMS, max 1.19 % there
// (not asserted here: the 0.4 % references at sun 85 deg cost an hour).
TEST(MethodOrders, HighAtTheDaylightTargetOnTheHazedSky) {
  const TestScene sc = LoadTestScene("hazed", TenNmGrid());
  const std::unique_ptr<SkyMethod> orders = HighOrders(sc);
  for (double sza : {30.0, 70.0}) {
    const std::vector<ColorEstimate> ref = PathY(sc, sza, SkyDirs(), 0.003);
    const std::vector<double> y = MethodY(sc, *orders, sza, SkyDirs());
    double ss = 0.0, noise = 0.0, worst = 0.0;
    for (size_t d = 0; d < y.size(); ++d) {
      const double e = y[d] / ref[d].xyz[1] - 1.0, sd = ref[d].xyz_stderr[1] / ref[d].xyz[1];
      std::printf("high vs path, hazed sun %.0f deg, dir %zu: %+.2f %% (path +- %.2f %%)\n", sza, d, 100.0 * e, 100.0 * sd);
      ss += e * e;
      noise += sd * sd;
      worst = std::max(worst, std::abs(e));
    }
    const double rms_corrected = std::sqrt(std::max(0.0, ss - noise) / static_cast<double>(y.size()));
    std::printf("high vs path, hazed sun %.0f deg: RMS %.2f %% (noise-corrected), max %.2f %%\n", sza,
                100.0 * rms_corrected, 100.0 * worst);
    EXPECT_LT(rms_corrected, 0.006) << "sun " << sza;
    EXPECT_LT(worst, 0.02) << "sun " << sza;
  }
}

// A cached path reference (ReadCachedReference) of the scene with a value per SkyDirs direction;
// one of another scene fails the test with the command that re-renders it.
std::optional<CachedReference> LoadCachedReference(const std::string& name, const TestScene& sc) {
  CachedReference c = ReadCachedReference(name, sc);
  EXPECT_TRUE(c.same_scene) << c.path << " is a reference of another scene: re-render it with `build/test/bin/"
                            << c.source.substr(0, c.source.find(" (")) << " -o " << c.path << "`";
  if (!c.same_scene) return std::nullopt;
  EXPECT_EQ(c.y.size(), SkyDirs().size()) << c.path;
  if (c.y.size() != SkyDirs().size()) return std::nullopt;
  return c;
}

// `high` against cached path references of the tests' scene at the other targets: under
// clouds in daylight (RMS <= 1 %, max <= 3 %) and in deep twilight (RMS <= 3 %), on the ten
// SkyDirs directions (the 20 nm test grid; references by bench_test_references with the cloud
// estimators, docs/sky-render.md "Clouds"). RMS noise-corrected (with ten 1 % references an RMS
// of 1 % reads 0.7-1.2 %, docs/sky-methods.md "Radius nodes under a cloud"); "worst" the largest
// |error| beyond 2 of the reference's standard errors. Measured (docs/sky-methods.md "Measured
// accuracy"; the droplets' 6.5 deg cone, "Truncation cone per component"): cloudy0 sun 70 deg
// 0.90 % / 0.10 % and sun 85 deg 1.69 % / 1.10 % (over the target: +3.0 % at 60 deg view zenith
// away from the sun and 88 deg 10 deg from its azimuth), cloudy1 sun 30 deg (22 radius nodes by the
// optical-depth rule) 0.91 % / 0.53 %, sun 70 deg 0.00 % / 0.16 %, sun 85 deg 1.47 % / 1.30 % (over
// the target: +3.3 % at 88 deg view zenith 10 deg from the sun's azimuth, +2.7 % at 89.5 deg 60 deg
// from it; a second seed's reference of the worst direction lies 1.5 % below the first), cloudy2
// sun 70 deg 1.17 % / 0.96 % and sun 85 deg 1.60 % / 1.44 % (every direction but two bright, the
// zenith +2.6 % at sun 85 deg; a 3 deg cone leaves the thin clouds at sun 70 and 85 deg 1.5-3.5 %
// RMS bright, up to +7.5 %),
// cloudy3 sun 30 deg (38 nodes) 0.16 % / 0 (16 nodes and a 3 deg cone: 4.29 % / 4.55 %), sun 70 deg
// 1.62 % / 1.52 % (over the target: the zenith +3.0 %, 60 deg view zenith away from the sun
// +3.5 %; reference 1380 CPU s), sun 85 deg 1.58 % / 1.56 % (over the target: +3.6 % at 75 deg
// view zenith 45 deg from the sun's azimuth; reference 2417 CPU s), clear sun 98 deg
// (0.4-1.1 % references, 2.9 % below the horizon; up to 2^23 paths) 1.59 % / 2.35 % (the
// worst towards the sun 2 deg above the horizon, -3.2 %; with 8 azimuths in the twilight split's
// part the horizon band 60-90 deg from the sun's azimuth was +4.3 and +6.3 %), clear sun 96 deg
// (0.4-1.5 % references) 0.80 % / 0.63 %, clear sun 100 deg
// (0.8-2.4 % references, seven of ten at the 2^23-path cap) 1.33 % / 1.06 % (the worst 75 deg
// from the zenith 45 deg from the sun's azimuth, +2.9 % against a 0.9 % reference), hazed sun 94
// deg (0.4-1 % references) 1.12 % / 1.46 % (the ground 5 deg below the horizon -3.1 %), hazed sun 98 deg
// (0.7-6.1 % references, seven of ten at the 2^23-path cap) 2.23 % / 2.64 % (towards the sun 2
// deg above the horizon +5.6 % against a 1.5 % reference; the references' noise, 2.9 % RMS, is
// as large as the error). The bounds are those figures plus 0.3 %.
TEST(MethodOrders, HighAgainstCachedPathReferences) {
  struct Case {
    const char* atmosphere;
    double sun_zenith_deg;
    const char* file;
    double max_rms, max_worst;
    const char* radius_nodes;  // Describe()'s line: the radius nodes by the optical-depth rule
  };
  const Case cases[] = {{"cloudy0", 70.0, "cloudy0_sun70.csv", 0.0120, 0.0040, "radius_nodes: 16\n"},
                        {"cloudy0", 85.0, "cloudy0_sun85.csv", 0.0199, 0.0140, "radius_nodes: 16\n"},
                        {"cloudy1", 30.0, "cloudy1_sun30.csv", 0.0121, 0.0083, "radius_nodes: 22\n"},
                        {"cloudy1", 70.0, "cloudy1_sun70.csv", 0.0030, 0.0046, "radius_nodes: 22\n"},
                        {"cloudy1", 85.0, "cloudy1_sun85.csv", 0.0177, 0.0160, "radius_nodes: 22\n"},
                        {"cloudy2", 70.0, "cloudy2_sun70.csv", 0.0147, 0.0126, "radius_nodes: 24\n"},
                        {"cloudy2", 85.0, "cloudy2_sun85.csv", 0.0190, 0.0174, "radius_nodes: 24\n"},
                        {"cloudy3", 30.0, "cloudy3_sun30.csv", 0.0046, 0.003, "radius_nodes: 38\n"},
                        {"cloudy3", 70.0, "cloudy3_sun70.csv", 0.0192, 0.0182, "radius_nodes: 38\n"},
                        {"cloudy3", 85.0, "cloudy3_sun85.csv", 0.0188, 0.0186, "radius_nodes: 38\n"},
                        {"clear", 96.0, "clear_sun96.csv", 0.0110, 0.0093, "radius_nodes: 16\n"},
                        {"clear", 98.0, "clear_sun98.csv", 0.0189, 0.0265, "radius_nodes: 16\n"},
                        {"clear", 100.0, "clear_sun100.csv", 0.0163, 0.0136, "radius_nodes: 16\n"},
                        {"hazed", 94.0, "hazed_sun94.csv", 0.0142, 0.0176, "radius_nodes: 16\n"},
                        {"hazed", 98.0, "hazed_sun98.csv", 0.0253, 0.0294, "radius_nodes: 16\n"}};
  std::string loaded;
  TestScene sc;
  std::unique_ptr<SkyMethod> orders;
  for (const Case& c : cases) {
    if (loaded != c.atmosphere) {
      sc = LoadTestScene(c.atmosphere);
      orders = HighOrders(sc);
      loaded = c.atmosphere;
    }
    EXPECT_NE(orders->Describe().find(c.radius_nodes), std::string::npos) << c.atmosphere << ":\n" << orders->Describe();
    const std::optional<CachedReference> found = LoadCachedReference(c.file, sc);
    if (!found) continue;
    const CachedReference& ref = *found;
    const std::vector<double> y = MethodY(sc, *orders, c.sun_zenith_deg, SkyDirs());
    double ss = 0.0, noise = 0.0, worst = 0.0;
    for (size_t d = 0; d < y.size(); ++d) {
      const double e = y[d] / ref.y[d] - 1.0, s = ref.y_stderr[d] / ref.y[d];
      std::printf("high vs cached path, %s sun %.0f deg, dir %zu: %+.2f %% (path +- %.2f %%)\n", c.atmosphere, c.sun_zenith_deg, d,
                  100.0 * e, 100.0 * s);
      ss += e * e;
      noise += s * s;
      worst = std::max(worst, std::abs(e) - 2.0 * s);
    }
    const double rms = std::sqrt(std::max(0.0, ss - noise) / static_cast<double>(y.size()));
    std::printf("high vs cached path, %s sun %.0f deg: RMS %.2f %% (noise-corrected), worst %.2f %%\n", c.atmosphere,
                c.sun_zenith_deg, 100.0 * rms, 100.0 * worst);
    EXPECT_LT(rms, c.max_rms) << c.atmosphere << " sun " << c.sun_zenith_deg;
    EXPECT_LT(worst, c.max_worst) << c.atmosphere << " sun " << c.sun_zenith_deg;
  }
}

// `high` with the sun on the horizon (sun zenith 90 deg), clear sky, on the horizon band 40 deg from
// the sun's azimuth, 0.5 and 3 deg above the horizon, where the sources fall steeply between the
// table build's sun nodes; with the nodes 1 deg apart from 80 deg and the log-linear blend from
// 85 deg: +0.13 / +0.30 % against 0.3-0.37 % references on 48 wavelengths (docs/sky-methods.md
// "The sun on the horizon"). Here ~0.8 % references (the path tracer's default cap of 2^20 paths) on
// the 10 nm grid, bound: the 2 % max beyond 2 of the reference's standard errors (a single
// seed's reference moves by its error: +0.84 / -0.30 % and +0.48 / -2.22 % with two estimators of
// the same radiance, docs/sky-render.md "Deep twilight"; 47-95 s).
TEST(MethodOrders, HighWithTheSunOnTheHorizonOnTheClearSky) {
  const TestScene sc = LoadTestScene("clear", TenNmGrid());
  const std::unique_ptr<SkyMethod> orders = HighOrders(sc);
  const std::vector<std::array<double, 3>> dirs = {Dir(89.5, 40), Dir(87, 40)};
  const std::vector<ColorEstimate> ref = PathY(sc, 90.0, dirs, 0.008);
  const std::vector<double> y = MethodY(sc, *orders, 90.0, dirs);
  for (size_t d = 0; d < y.size(); ++d) {
    const double e = y[d] / ref[d].xyz[1] - 1.0;
    const double rel_se = ref[d].xyz_stderr[1] / ref[d].xyz[1];
    std::printf("high vs path, clear sun 90 deg, dir %zu: %+.2f %% (path +- %.2f %%)\n", d, 100.0 * e, 100.0 * rel_se);
    EXPECT_LT(std::abs(e) - 2.0 * rel_se, 0.02) << "dir " << d;
  }
}

// The second order alone - `orders` with 2 orders against the path tracer counting scatterings up
// to 2 - isolates the scattering kernel, which is where the hazed sky's error comes from
// (docs/sky-methods.md "Scattering kernel"): hazed, sun 70 deg, five directions (the zenith, 10
// deg from the sun, across, away from the sun at 80 deg, 30 deg off it at 85 deg), 0.5 %
// references, the 21-wavelength test grid. Measured: `high`'s kernel (integrated against the
// interpolation's basis) with 24 azimuths and one 3 deg cone +0.2, -0.2, +0.7, -0.5, +1.5 % (RMS
// 0.8 %), and high's 36 azimuths and 1 deg aerosol cone within the same bounds; `medium`'s (phase
// at the nodes, 8 azimuths, 5 deg) -2.1, -3.8, +2.1, -0.4, +1.7 % (RMS
// 2.3 %); medium's kernel with a 3 deg cone -3.5 % at the zenith (the lobe counted as filling the
// zenith node's cap, and the row normalisation taking the excess from every other direction).
// Bounds: the measured figures plus the references' noise, and high at most 0.6 x medium's RMS.
TEST(MethodOrders, SecondOrderWithTheBasisKernel) {
  const TestScene sc = LoadTestScene("hazed");
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 0), Dir(60, 90), Dir(80, 180), Dir(85, 30)};
  PathTracerSettings ps;
  ps.target_relative_error = 0.005;
  ps.min_paths = 1024;
  ps.max_order = 2;
  PathTracer pt(sc.model, sc.weights, ps);
  std::vector<ColorEstimate> ref(dirs.size());
  const glm::dvec3 x(0, 0, sc.model.bottom_radius_m + 1.0);
  tbb::parallel_for(size_t{0}, dirs.size(), [&](size_t d) {
    ref[d] = pt.Radiance(x, glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]), DirectionFromAngles(70.0 * kDeg, 0), 700 + d);
  });
  auto errors = [&](const char* quality, int truncation_deg, double* rms, double* worst) {
    SkyMethodOptions o;
    o.quality = ParseQuality(quality, "quality");
    o.orders = 2;
    if (truncation_deg > 0) o.table_size["truncation_deg"] = truncation_deg;
    const std::vector<double> y = MethodY(sc, *MakeSkyMethod("orders", sc.model, o, {}), 70.0, dirs);
    double ss = 0.0;
    *worst = 0.0;
    for (size_t d = 0; d < dirs.size(); ++d) {
      const double e = y[d] / ref[d].xyz[1] - 1.0;
      std::printf("orders <= 2 vs path <= 2, %s (truncation %d), dir %zu: %+.2f %% (path +- %.2f %%)\n", quality,
                  truncation_deg, d, 100.0 * e, 100.0 * ref[d].xyz_stderr[1] / ref[d].xyz[1]);
      ss += e * e;
      *worst = std::max(*worst, std::abs(e));
    }
    *rms = std::sqrt(ss / static_cast<double>(dirs.size()));
  };
  double high_rms, high_max, med_rms, med_max, med3_rms, med3_max;
  errors("high", 0, &high_rms, &high_max);
  errors("medium", 0, &med_rms, &med_max);
  errors("medium", 3, &med3_rms, &med3_max);
  EXPECT_LT(high_rms, 0.012);
  EXPECT_LT(high_max, 0.022);
  EXPECT_LT(med_rms, 0.035);
  EXPECT_LT(med_max, 0.05);
  EXPECT_LT(high_rms, 0.6 * med_rms);
  EXPECT_LT(high_rms, 0.6 * med3_rms);
}

// `low` orders tables with the given table keys and order count on the test scene: the radiance at
// every 11 deg of view zenith and every az_step deg of azimuth, at each sun, concatenated.
std::vector<double> LowOrdersOnAGrid(const TestScene& sc, int orders, const std::map<std::string, int>& keys,
                                     const std::vector<double>& suns, double az_step) {
  std::vector<std::array<double, 3>> dirs;
  for (double vz = 0.0; vz < 180.0; vz += 11.0) {
    for (double az = 0.0; az <= 180.0; az += az_step) dirs.push_back(Dir(vz, az));
  }
  SkyMethodOptions o;
  o.quality = Quality::kLow;
  o.orders = orders;
  o.table_size = keys;
  const auto m = MakeSkyMethod("orders", sc.model, o, {});
  std::vector<double> L;
  for (double sun : suns) {
    std::vector<double> v;
    m->Radiance(1.0, sun * kDeg, dirs, &v);
    L.insert(L.end(), v.begin(), v.end());
  }
  return L;
}

// The largest |b / a - 1| (every a > 0).
double WorstRelative(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_GT(a[i], 0.0) << i;
    worst = std::max(worst, std::abs(b[i] / a[i] - 1.0));
  }
  return worst;
}

// The scattering kernel applied in azimuthal cosine modes (the default) is the (nd x nd) matrix
// it replaces, to float rounding with float kernels: for the phase at the nodes, for the basis
// kernel with the even azimuth blend (whose two end intervals are explicit columns) and with the
// linear blend; and to the binary16 kernels' rounding (2^-12 relative per value) with those, the
// default. Measured: <= 9e-7 and <= 2.5e-4 relative on the hazed sky (3 orders, 25 x 16
// directions, sun 30-93 deg).
TEST(MethodOrders, ModalKernelIsTheMatrixKernel) {
  const TestScene sc = LoadTestScene("hazed");
  for (const auto& [ksub, even] : std::vector<std::pair<int, int>>{{0, 1}, {2, 1}, {2, 0}}) {
    const int kernel_sub = ksub, azimuth_even = even;  // a lambda may not capture structured bindings (C++20, clang 14)
    auto orders = [&](int modal, int half) {
      return LowOrdersOnAGrid(sc, 3,
                              {{"kernel_sub", kernel_sub}, {"azimuth_even", azimuth_even}, {"kernel_modal", modal}, {"kernel_half", half}, {"azimuth", 7}},
                              {40.0, 86.0}, 15.0);
    };
    const std::vector<double> matrix = orders(0, 0);
    const double worst = WorstRelative(matrix, orders(1, 0)), worst_half = WorstRelative(matrix, orders(1, 1));
    std::printf("kernel_sub %d, even blend %d: modal vs matrix, max %.2g relative (float kernels), %.2g (binary16)\n", ksub, even, worst,
                worst_half);
    EXPECT_LT(worst, 1e-5);
    EXPECT_LT(worst_half, 5e-4);
  }
}

// The transport by families (the default: each step's radius/view corners blended once for all
// sun and azimuth nodes) is the cell-by-cell 16-corner gather, to float rounding: daylight, the
// sun on the horizon and twilight (where the upper and lower radius corners take the log-linear
// factor apart), with the ground below. Low tables with 5 orders on the test grid. Measured:
// 3.3e-7 at worst.
TEST(MethodOrders, SplitGatherIsTheCellGather) {
  const TestScene sc = LoadTestScene("hazed");
  const std::vector<double> cells = LowOrdersOnAGrid(sc, 5, {{"gather_split", 0}}, {40.0, 90.0, 95.5}, 30.0);
  const std::vector<double> split = LowOrdersOnAGrid(sc, 5, {{"gather_split", 1}}, {40.0, 90.0, 95.5}, 30.0);
  const double worst = WorstRelative(cells, split);
  std::printf("split vs cell gather: max %.2g relative\n", worst);
  EXPECT_LT(worst, 1e-5);
}

// The same bytes at 1 and 2 threads (tables built in parallel, reductions in a fixed order).
TEST(MethodOrders, SameResultAtAnyThreadCount) {
  const TestScene sc = LoadTestScene("clear");
  SkyMethodOptions o;
  o.quality = Quality::kLow;
  std::vector<double> a, b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    MakeSkyMethod("orders", sc.model, o, {})->Radiance(1.0, 80.0 * kDeg, SkyDirs(), &a);
  }
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    MakeSkyMethod("orders", sc.model, o, {})->Radiance(1.0, 80.0 * kDeg, SkyDirs(), &b);
  }
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

// The step positions stored for every radius node, for some (a budget of 4 MiB: 5 of low's 10 at
// 0.74 MiB each) and for none (computed per lookup): the same bytes, in daylight and in twilight.
TEST(MethodOrders, StoredAndComputedStepPositionsAreTheSameSky) {
  const TestScene sc = LoadTestScene("hazed");
  // One solve per budget (its tables hold every sun node), read at both sun angles.
  auto sky = [&](int mib) {
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    o.table_size["step_positions_mib"] = mib;
    const std::unique_ptr<SkyMethod> m = MakeSkyMethod("orders", sc.model, o, {});
    std::vector<double> y, y2;
    m->Radiance(1.0, 60.0 * kDeg, SkyDirs(), &y);
    m->Radiance(1.0, 95.0 * kDeg, SkyDirs(), &y2);
    y.insert(y.end(), y2.begin(), y2.end());
    return y;
  };
  const std::vector<double> all = sky(64), some = sky(4), none = sky(0);
  ASSERT_EQ(all.size(), 2 * SkyDirs().size() * sc.model.wavelengths());
  ASSERT_EQ(all.size(), none.size());
  for (size_t i = 0; i < all.size(); ++i) {
    ASSERT_EQ(all[i], some[i]) << i;
    ASSERT_EQ(all[i], none[i]) << i;
  }
}

// The solve in wavelength batches (solve.h: each batch also solves the reference wavelength, whose
// decisions every batch shares) against one solve: the same bytes for the sky, daylight and
// twilight, and for a view segment, which reads the sources J_ms. low hazed, 21 wavelengths, its
// tables 0.75 MiB per wavelength: a budget of 6 MiB gives three batches of 8, 8 and 7 solved
// (the reference, the middle one, in each), 1 MiB the smallest batches, 20 (one wavelength and
// the reference; the reference's batch two of its own).
TEST(MethodOrders, WavelengthBatchesAreTheSameSky) {
  const TestScene sc = LoadTestScene("hazed");
  ViewSegment seg;
  seg.max_distance_m = 20e3;
  auto sky = [&](int mib, const std::string& batches, int positions_mib = 0) {
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    o.segments = true;
    if (mib > 0) o.table_size["solve_tables_mib"] = mib;
    if (positions_mib > 0) o.table_size["step_positions_mib"] = positions_mib;
    const std::unique_ptr<SkyMethod> m = MakeSkyMethod("orders", sc.model, o, {});
    EXPECT_NE(m->Describe().find("wavelength_batches: " + batches + "\n"), std::string::npos) << m->Describe();
    std::vector<double> y, more;
    m->Radiance(1.0, 60.0 * kDeg, SkyDirs(), &y);
    m->Radiance(1.0, 95.0 * kDeg, SkyDirs(), &more);
    y.insert(y.end(), more.begin(), more.end());
    m->SegmentRadiance(1.0, 60.0 * kDeg, SkyDirs(), seg, &more);
    y.insert(y.end(), more.begin(), more.end());
    return y;
  };
  const std::vector<double> one = sky(0, "1"), three = sky(6, "3"), each = sky(1, "20");
  // 12 MiB: batches of 16 and 6 solved; with 1 MiB of step positions the smaller batch stores
  // more radius nodes' positions than the larger (the 7 MiB its tables leave), the same sky.
  const std::vector<double> two_few = sky(12, "2", 1);
  ASSERT_EQ(one.size(), 3 * SkyDirs().size() * sc.model.wavelengths());
  ASSERT_EQ(one.size(), each.size());
  ASSERT_EQ(one.size(), two_few.size());
  for (size_t i = 0; i < one.size(); ++i) {
    ASSERT_EQ(one[i], three[i]) << i;
    ASSERT_EQ(one[i], each[i]) << i;
    ASSERT_EQ(one[i], two_few[i]) << i;
  }
  // A sky alone (the solve in place: two fields per cell, the observer's codes) in batches of
  // one wavelength and the reference, against its one solve and the sky of the solve above.
  auto sky_alone = [&](int mib) {
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    if (mib > 0) o.table_size["solve_tables_mib"] = mib;
    const std::unique_ptr<SkyMethod> m = MakeSkyMethod("orders", sc.model, o, {});
    EXPECT_NE(m->Describe().find(mib > 0 ? "wavelength_batches: 20\n" : "wavelength_batches: 1\n"), std::string::npos)
        << m->Describe();
    std::vector<double> y, more;
    m->Radiance(1.0, 60.0 * kDeg, SkyDirs(), &y);
    m->Radiance(1.0, 95.0 * kDeg, SkyDirs(), &more);
    y.insert(y.end(), more.begin(), more.end());
    return y;
  };
  const std::vector<double> alone = sky_alone(0), alone_each = sky_alone(1);
  ASSERT_EQ(alone.size(), 2 * SkyDirs().size() * sc.model.wavelengths());
  for (size_t i = 0; i < alone.size(); ++i) {
    ASSERT_EQ(alone[i], alone_each[i]) << i;
    ASSERT_EQ(alone[i], one[i]) << i;
  }
}

// A sky alone (no view segments) transports each order into L in place and keeps the observer's
// L_{n-1} aside (solve.cpp, OrderTables); with segments the solve keeps L, J and L_next and the
// ratio codes of every element. The two forms give the same bytes, with each of the tails: the
// per-element one (hazed), the dominant mode's at the cap (hazed, 5 orders, no early tail) and
// the two modes' (cloudy5's deck).
TEST(MethodOrders, InPlaceSolveIsTheKeptSourcesSolve) {
  struct Case {
    const char* atmosphere;
    std::map<std::string, int> overrides;
    int orders;
    const char* tail;  // Describe()'s tail_extrapolated line
  };
  const Case cases[] = {{"hazed", {}, 0, "tail_extrapolated: true\n"},
                        {"hazed", {{"early_tail", 0}}, 5, "tail_extrapolated: true (dominant mode)\n"},
                        {"cloudy5", {}, 0, "tail_extrapolated: true (two modes)\n"}};
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 90), Dir(88, 180), Dir(95, 30)};
  for (const Case& c : cases) {
    const TestScene sc = LoadTestScene(c.atmosphere);
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    o.table_size = c.overrides;
    o.orders = c.orders;
    const std::unique_ptr<SkyMethod> sky = MakeSkyMethod("orders", sc.model, o, {});
    o.segments = true;
    const std::unique_ptr<SkyMethod> kept = MakeSkyMethod("orders", sc.model, o, {});
    EXPECT_NE(sky->Describe().find(c.tail), std::string::npos) << c.atmosphere << ":\n" << sky->Describe();
    EXPECT_EQ(sky->Describe(), kept->Describe()) << c.atmosphere;
    for (double sun_deg : {30.0, 85.0, 95.0}) {
      std::vector<double> a, b;
      sky->Radiance(0.0, sun_deg * kDeg, dirs, &a);
      kept->Radiance(0.0, sun_deg * kDeg, dirs, &b);
      EXPECT_EQ(a, b) << c.atmosphere << " sun " << sun_deg;
    }
  }
}

// The sun on the horizon: inside the table build a table ray's sources are blended between the
// sun nodes of each step's local sun angle, and from 80 to 90 deg they fall steeply and convexly.
// The default nodes (1 deg from 80 deg, log-linear blend from 85 deg) against 0.2 deg ones
// (low_sun_step_x10 2), medium, on the horizon band with the sun at 90 deg: within 1 % (measured
// -0.15 to -0.44 %; docs/sky-methods.md "The sun on the horizon").
TEST(MethodOrders, SunOnTheHorizonConvergedInTheSunNodes) {
  const TestScene sc = LoadTestScene("clear");
  const std::vector<std::array<double, 3>> dirs = {Dir(89.5, 40), Dir(89.5, 90), Dir(87, 40), Dir(80, 40), Dir(60, 40)};
  SkyMethodOptions o;
  o.quality = Quality::kMedium;
  SkyMethodOptions fine = o;
  fine.table_size["low_sun_step_x10"] = 2;
  const std::vector<double> y = MethodY(sc, *MakeSkyMethod("orders", sc.model, o, {}), 90.0, dirs);
  const std::vector<double> y_fine = MethodY(sc, *MakeSkyMethod("orders", sc.model, fine, {}), 90.0, dirs);
  for (size_t d = 0; d < dirs.size(); ++d) {
    std::printf("sun 90 deg, dir %zu: default nodes %.4g, 0.2 deg nodes %.4g (%+.2f %%)\n", d, y[d], y_fine[d], 100.0 * (y[d] / y_fine[d] - 1.0));
    EXPECT_NEAR(y[d] / y_fine[d], 1.0, 0.01) << "dir " << d;
  }
}

// The twilight split of `high` (transport/orders/split.h: the daylight tables to sun zenith 93
// deg, the twilight tables with 16 azimuths and medium's kernel and cone from 88 deg, blended over
// 90-91 deg) against one solve of all 42 sun nodes (split_from_deg 0), hazed, on a 40 nm grid (11
// wavelengths) with 8 radius nodes in both and 18 azimuths in the daylight part and the one solve
// (so that the two builds take ~6 s), over 84 directions (12 view zeniths x 7 azimuths; 91 deg is
// the ground's dark band just below the horizon, which medium's view nodes blur: 431 % max with
// them). Daylight, sun 30 / 70 / 85 / 89 / 90 deg: the same tables but for the sun nodes past 93
// deg, which reach the daylight sky through the table rays' far ends only; measured <= 0 / 0 /
// 3.9e-7 / 1.6e-5 / 1.2e-4 relative per wavelength at worst, bound 1e-3. Twilight, sun 95 deg:
// measured Y RMS 0.81 %, max 1.79 %, bounds 1.2 % and 2.5 % (with 8 twilight azimuths 1.39 % and
// 3.05 %: the bounds tell them apart; the twilight target is 3 % RMS against the path tracer, of
// which the split should take a small part). Across the blend zone (sun 90 to 91 deg by 0.25 deg)
// each direction's Y falls step by step, and no step is larger than 1.5 x the one solve's over the
// same quarter degree (measured 1.03 x): no jump between the LUT's sun slices where the parts meet.
TEST(MethodOrders, TwilightSplitIsHighInDaylightAndSmoothIntoTwilight) {
  SceneOptions so;
  so.step_nm = 40.0;
  const TestScene sc = LoadTestScene("hazed", so);
  SkyMethodOptions split;
  split.quality = Quality::kHigh;
  split.table_size = {{"radius", 8}, {"azimuth", 18}};
  SkyMethodOptions one = split;
  one.table_size["split_from_deg"] = 0;
  const std::unique_ptr<SkyMethod> ms = MakeSkyMethod("orders", sc.model, split, {});
  const std::unique_ptr<SkyMethod> mo = MakeSkyMethod("orders", sc.model, one, {});
  EXPECT_NE(ms->Describe().find("twilight_split: "), std::string::npos);
  EXPECT_EQ(mo->Describe().find("twilight"), std::string::npos);
  std::vector<std::array<double, 3>> dirs;
  for (double vz : {0.0, 20.0, 40.0, 60.0, 75.0, 85.0, 88.0, 89.5, 91.0, 92.0, 100.0, 130.0}) {
    for (double az = 0.0; az <= 180.0; az += 30.0) dirs.push_back(Dir(vz, az));
  }
  for (double sza : {30.0, 70.0, 85.0, 89.0, 90.0}) {
    std::vector<double> a, b;
    mo->Radiance(1.0, sza * kDeg, dirs, &a);
    ms->Radiance(1.0, sza * kDeg, dirs, &b);
    const double worst = WorstRelative(a, b);
    std::printf("split vs one solve, sun %.0f deg: max %.2g relative\n", sza, worst);
    EXPECT_LT(worst, 1e-3) << "sun " << sza;
  }
  {
    const std::vector<double> a = MethodY(sc, *mo, 95.0, dirs), b = MethodY(sc, *ms, 95.0, dirs);
    double ss = 0.0, worst = 0.0;
    for (size_t d = 0; d < a.size(); ++d) {
      const double e = b[d] / a[d] - 1.0;
      ss += e * e;
      worst = std::max(worst, std::abs(e));
    }
    const double rms = std::sqrt(ss / static_cast<double>(a.size()));
    std::printf("split vs one solve, sun 95 deg: Y RMS %.2f %%, max %.2f %%\n", 100.0 * rms, 100.0 * worst);
    EXPECT_LT(rms, 0.012);
    EXPECT_LT(worst, 0.025);
  }
  std::vector<std::vector<double>> ys, yo;
  for (double sza = 90.0; sza <= 91.0 + 1e-9; sza += 0.25) {
    ys.push_back(MethodY(sc, *ms, sza, dirs));
    yo.push_back(MethodY(sc, *mo, sza, dirs));
  }
  double worst_ratio = 0.0;
  for (size_t d = 0; d < dirs.size(); ++d) {
    for (size_t k = 0; k + 1 < ys.size(); ++k) {
      EXPECT_LT(ys[k + 1][d], ys[k][d]) << "dir " << d << " step " << k;
      const double ratio = (ys[k][d] - ys[k + 1][d]) / (yo[k][d] - yo[k + 1][d]);
      worst_ratio = std::max(worst_ratio, ratio);
    }
  }
  std::printf("split across the blend zone: largest step %.3f x the one solve's\n", worst_ratio);
  EXPECT_LT(worst_ratio, 1.5);
}

// Capping the orders removes light monotonically, and the default stopping rule (orders until
// the next adds < 0.1 % or the geometric tail is that accurate, then the tail with a ratio per
// table element) is within 0.5 % of 40 explicit orders at every direction of the hazed sky
// (measured: 0.3 %; one global ratio: 0.55 %; low's tolerance 3e-3: 2.8 % at the horizon).
TEST(MethodOrders, OrdersConvergeAndTheTailIsAccurate) {
  const TestScene sc = LoadTestScene("hazed");
  std::vector<double> prev;
  for (int n : {2, 3, 5}) {
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    o.orders = n;
    o.table_size["early_tail"] = 0;
    const std::vector<double> y = MethodY(sc, *MakeSkyMethod("orders", sc.model, o, {}), 60.0, SkyDirs());
    if (!prev.empty()) {
      for (size_t d = 0; d < y.size(); ++d) EXPECT_GE(y[d], prev[d] * (1.0 - 1e-6)) << n << " orders, dir " << d;
    }
    prev = y;
  }
  SkyMethodOptions all;
  all.quality = Quality::kLow;
  all.orders = 40;
  all.order_tolerance = 1e-7;
  all.table_size["early_tail"] = 0;
  SkyMethodOptions dflt;
  dflt.quality = Quality::kLow;
  dflt.order_tolerance = 1e-3;  // medium's and high's stopping rule on low's tables
  const std::vector<double> y_all = MethodY(sc, *MakeSkyMethod("orders", sc.model, all, {}), 60.0, SkyDirs());
  const std::vector<double> y_def = MethodY(sc, *MakeSkyMethod("orders", sc.model, dflt, {}), 60.0, SkyDirs());
  for (size_t d = 0; d < y_all.size(); ++d) EXPECT_NEAR(y_def[d] / y_all[d], 1.0, 0.005) << "dir " << d;
}

// A thin, optically thick, conservative layer - a 2 km water-cloud-like tent of optical depth 8
// at 3.5-5.5 km, Henyey-Greenstein g = 0.8, over a ground of albedo 0.3 - where the successive
// orders converge slowly (the ratio of successive orders creeps up to ~0.93) and the sources
// change fast with altitude. The radius nodes follow the optical depth, a table ray's steps are
// integrated exponentially with energy-conserving weights and take their sources at their
// centroid in optical depth, and the view nodes are in angle. `medium` ends here at order 33 with
// the tail of the dominant mode and the next (asserted: a tail). Against the path tracer (2 %
// references) at the four directions, sun 30 deg: measured +1.8, +0.2, +4.2, +6.1 %; the bound,
// 7 %, is the worst of those plus a third of the references' noise. The remaining error is the view resolution
// (docs/sky-methods.md "Thick cloud layers").
// A lossless cloud layer of optical depth 8 (HG g 0.8) between 3.5 and 5.5 km, a tent in
// extinction peaking at 4.5 km, over a ground of albedo 0.3, two wavelengths, unit sun.
static AtmosphereModel ThickTentLayer() {
  const double R = 6371e3;
  AtmosphereModel m;
  m.bottom_radius_m = R;
  m.top_radius_m = R + 20e3;
  m.altitude_m = {0.0, 3500.0, 4500.0, 5500.0, 20e3};
  m.wavelength_nm = {500.0, 600.0};
  MediumComponent c;
  c.name = "aerosol.cloud";
  c.phase = std::make_shared<HenyeyGreensteinPhase>(std::vector<double>{0.8, 0.8});
  for (double sigma : {0.0, 0.0, 8e-3, 0.0, 0.0}) {  // m^-1: the tent's area is 8e-3 x 1000 m = 8
    for (int w = 0; w < 2; ++w) {
      c.scattering.push_back(sigma);
      c.absorption.push_back(0.0);
    }
  }
  m.components.push_back(c);
  m.ground_albedo = {0.3, 0.3};
  m.sun.irradiance = {1.0, 1.0};
  m.Finalize();
  return m;
}

TEST(MethodOrders, ThickCloudLayerConvergesWithinItsMeasuredError) {
  const double R = 6371e3;
  const AtmosphereModel m = ThickTentLayer();
  const std::vector<std::array<double, 3>> weights = {{0.0, 0.5, 0.0}, {0.0, 0.5, 0.0}};
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 0), Dir(60, 180), Dir(85, 90)};
  SkyMethodOptions o;
  o.quality = Quality::kMedium;
  std::unique_ptr<SkyMethod> orders = MakeSkyMethod("orders", m, o, {});
  const std::string desc = orders->Describe();
  std::printf("%s", desc.c_str());
  EXPECT_NE(desc.find("tail_extrapolated: true"), std::string::npos) << "no tail";
  std::vector<double> L;
  orders->Radiance(1.0, 30.0 * kDeg, dirs, &L);
  PathTracerSettings ps;
  ps.target_relative_error = 0.02;
  ps.min_paths = 1024;
  PathTracer pt(m, weights, ps);
  std::vector<ColorEstimate> ref(dirs.size());
  tbb::parallel_for(size_t{0}, dirs.size(), [&](size_t d) {
    ref[d] = pt.Radiance(glm::dvec3(0, 0, R + 1.0), glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]),
                         DirectionFromAngles(30.0 * kDeg, 0), 500 + d);
  });
  for (size_t d = 0; d < dirs.size(); ++d) {
    const double y = 0.5 * (L[d * 2] + L[d * 2 + 1]);
    const double e = y / ref[d].xyz[1] - 1.0;
    std::printf("thick layer, dir %zu: orders %.5g path %.5g +- %.1f %%: %+.1f %%\n", d, y, ref[d].xyz[1],
                100.0 * ref[d].xyz_stderr[1] / ref[d].xyz[1], 100.0 * e);
    EXPECT_TRUE(std::isfinite(y) && y > 0.0);
    // Measured +1.8, +0.2, +4.2, +6.1 % (path 2 %).
    EXPECT_LT(std::abs(e), 0.07) << "dir " << d;
  }
}

// The table rays' quadrature through a thick layer: the sky under the tau-8 layer with 40 steps
// per table ray (medium) and with 160. A step takes its sources at its centroid in optical
// depth, so the step that straddles the cloud's edge takes them where its optical depth lies, in
// the cloud, and the sky does not depend on the step count. Measured: 40 and 160 steps within
// 0.4 %.
TEST(MethodOrders, TableRayStepsConvergeThroughAThickLayer) {
  const AtmosphereModel m = ThickTentLayer();
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 0), Dir(60, 180), Dir(85, 90)};
  std::vector<double> L[2];
  for (int k = 0; k < 2; ++k) {
    SkyMethodOptions o;
    o.quality = Quality::kMedium;
    o.table_size["ray_steps"] = k == 0 ? 40 : 160;
    MakeSkyMethod("orders", m, o, {})->Radiance(1.0, 30.0 * kDeg, dirs, &L[k]);
  }
  for (size_t d = 0; d < dirs.size(); ++d) {
    const double y40 = 0.5 * (L[0][d * 2] + L[0][d * 2 + 1]), y160 = 0.5 * (L[1][d * 2] + L[1][d * 2 + 1]);
    std::printf("thick layer, dir %zu: 40 steps %.5g, 160 steps %.5g: %+.2f %%\n", d, y40, y160, 100.0 * (y40 / y160 - 1.0));
    EXPECT_LT(std::abs(y40 / y160 - 1.0), 0.015) << "dir " << d;
  }
}

// Under cloudy5's deck (water droplets, optical depth 16) the orders converge: the table rays'
// step weights conserve energy, so each order adds less than the last and the ratio of
// successive orders settles (at ~0.955 at 600 nm). medium's stopping rule ends before its
// 40-order cap with the tail of the dominant mode and the next (solve.cpp, SecondMode); against
// every order to 90 and the dominant mode's tail there (a tail 20x smaller). Measured on this
// grid (40 nm): the rule stops at order 31, +0.16 ... +0.23 % (medium's tolerance is 1e-3).
TEST(MethodOrders, OrdersConvergeUnderAThickWaterCloud) {
  SceneOptions so;
  so.step_nm = 40.0;
  const TestScene sc = LoadTestScene("cloudy5", so);
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 0), Dir(60, 180), Dir(85, 90)};
  std::vector<double> y[2];
  for (int i = 0; i < 2; ++i) {
    SkyMethodOptions o;
    o.quality = Quality::kMedium;
    o.orders = i == 0 ? 40 : 90;
    if (i == 1) {
      o.order_tolerance = 1e-7;
      o.table_size["early_tail"] = 0;
    }
    const auto m = MakeSkyMethod("orders", sc.model, o, {});
    const std::string desc = m->Describe();
    std::printf("max orders %d:\n%s", o.orders, desc.c_str());
    if (i == 0) {
      EXPECT_NE(desc.find("tail_extrapolated: true (two modes)"), std::string::npos) << "no two-mode tail";
      EXPECT_EQ(desc.find("orders_computed: 40"), std::string::npos) << "the cap was reached";
    } else {
      EXPECT_NE(desc.find("orders_computed: 90"), std::string::npos) << "the cap was not reached";
      EXPECT_NE(desc.find("tail_extrapolated: true (dominant mode)"), std::string::npos) << "the orders did not settle";
    }
    y[i] = MethodY(sc, *m, 30.0, dirs);
  }
  for (size_t d = 0; d < dirs.size(); ++d) {
    std::printf("dir %zu: Y %.6g (the rule) %.6g (90 orders): %+.3f %%\n", d, y[0][d], y[1][d], 100.0 * (y[0][d] / y[1][d] - 1.0));
    EXPECT_GT(y[0][d], 0.0);
    EXPECT_NEAR(y[0][d] / y[1][d], 1.0, 0.005) << d;
  }
}

// Diffusion synthetic acceleration (transport/orders/acceleration.h) under cloudy5's deck: the
// accelerated series ends in fewer orders at the same sky. low, 40 nm grid, sun 30 deg; the plain
// rule, the accelerated one (dsa_from_tau_x10 1: every column) and every order to 90 without a
// tail (the converged sky). Measured: 24 orders plain, 13 accelerated; Y off the converged sky
// +0.63 ... +0.83 % plain, -0.46 ... +0.37 % accelerated (bound 1 %; low's tolerance is 3e-3). The
// accelerated solve in wavelength batches is the same sky, byte for byte: every decision reads
// the reference wavelength and the correction is per wavelength.
TEST(MethodOrders, AcceleratedOrdersAreTheSeriesInFewerOrders) {
  SceneOptions so;
  so.step_nm = 40.0;
  const TestScene sc = LoadTestScene("cloudy5", so);
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 0), Dir(60, 180), Dir(85, 90), Dir(89.5, 30)};
  auto orders_of = [](const std::string& desc) {
    const size_t at = desc.find("orders_computed: ");
    return at == std::string::npos ? -1 : std::atoi(desc.c_str() + at + 17);
  };
  std::vector<double> y[4];
  int n[4];
  for (int i = 0; i < 4; ++i) {
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    if (i == 1 || i == 3) o.table_size["dsa_from_tau_x10"] = 1;
    if (i == 2) {
      o.orders = 90;
      o.order_tolerance = 1e-7;
      o.table_size["early_tail"] = 0;
    }
    if (i == 3) o.table_size["solve_tables_mib"] = 1;  // a batch per two wavelengths
    const auto m = MakeSkyMethod("orders", sc.model, o, {});
    const std::string desc = m->Describe();
    n[i] = orders_of(desc);
    EXPECT_EQ(desc.find("acceleration: diffusion") != std::string::npos, i == 1 || i == 3) << desc;
    if (i == 3) {
      EXPECT_EQ(desc.find("wavelength_batches: 1\n"), std::string::npos) << desc;
    }
    y[i] = MethodY(sc, *m, 30.0, dirs);
  }
  std::printf("orders: plain %d, accelerated %d, converged %d\n", n[0], n[1], n[2]);
  EXPECT_LT(n[1], n[0]);
  EXPECT_EQ(y[3], y[1]) << "the batches differ";
  for (size_t d = 0; d < dirs.size(); ++d) {
    std::printf("dir %zu: Y plain %+.3f %%, accelerated %+.3f %% off %.6g (90 orders)\n", d, 100.0 * (y[0][d] / y[2][d] - 1.0),
                100.0 * (y[1][d] / y[2][d] - 1.0), y[2][d]);
    EXPECT_NEAR(y[1][d] / y[2][d], 1.0, 0.01) << d;
  }
}

// A phase function that is all forward peak: a Gaussian lobe of sigma 0.5 deg (weight 1 - a) and an
// isotropic floor a = 0.005. Sampling: the floor, or the lobe by its small-angle form
// (theta = sigma sqrt(-2 ln(1 - u)), exact while sin(theta) = theta: to 4e-5 at 1 deg).
class ForwardLobePhase : public PhaseModel {
 public:
  static constexpr double kSigma = 0.5 * kDeg, kFloor = 0.005;
  double Eval(size_t, double mu) const override {
    const double th = std::acos(std::clamp(mu, -1.0, 1.0));
    return (1.0 - kFloor) * std::exp(-th * th / (2.0 * kSigma * kSigma)) / (2.0 * kPi * kSigma * kSigma) + kFloor / (4.0 * kPi);
  }
  double SampleMu(size_t, double u) const override {
    if (u < kFloor) return 2.0 * u / kFloor - 1.0;
    const double v = (u - kFloor) / (1.0 - kFloor);
    return std::cos(kSigma * std::sqrt(-2.0 * std::log(1.0 - v)));
  }
  std::string Name() const override { return "forward-lobe"; }
};

// The limit behind the TMS attenuation (Nakajima & Tanaka 1988): a layer of scatterers whose
// phase function lies inside the truncation cone (ForwardLobePhase: 99.5 % within 2 deg) only
// moves sunlight by a degree or two, so the sky away from the sun is the sky without it but for
// the isotropic floor. The clear sky with such a layer of optical depth 1 at 3.5-5.5 km against the
// clear sky with an isotropic layer of the floor's optical depth (0.005) there, medium, sun 50 deg,
// the 35 directions 15 deg or more from the sun: within 1 % (measured 0.17 % RMS, max 0.29 %). With
// ss_scaled 0 the exact single scattering is attenuated by the unscaled medium, the light scattered
// into the cone is counted by neither term, and the sky comes out 57 % dark on average, 72 % at
// worst (asserted: RMS above 20 %); that form puts the thin water cloud of cloudy1 17-53 % below
// the path tracer (docs/sky-methods.md "TMS attenuation").
TEST(MethodOrders, ForwardOnlyLayerLeavesTheSkyAwayFromTheSun) {
  const TestScene sc = LoadTestScene("clear");
  // The clear sky with a layer at 3.5-5.5 km of the forward scatterers (tau 1), and, as the
  // reference, with a layer of isotropic scatterers of the floor's share (tau a).
  auto with_layer = [&](std::shared_ptr<const PhaseModel> phase, double tau) {
    AtmosphereModel m = sc.model;
    MediumComponent c;
    c.name = "aerosol.layer";
    c.phase = std::move(phase);
    const size_t nl = m.levels(), nw = m.wavelengths();
    c.scattering.assign(nl * nw, 0.0);
    c.absorption.assign(nl * nw, 0.0);
    for (size_t l = 0; l < nl; ++l) {
      if (m.altitude_m[l] < 3500.0 || m.altitude_m[l] > 5500.0) continue;
      for (size_t w = 0; w < nw; ++w) c.scattering[l * nw + w] = tau / 2000.0;  // m^-1
    }
    m.components.push_back(c);
    m.Finalize();
    return m;
  };
  const AtmosphereModel with = with_layer(std::make_shared<ForwardLobePhase>(), 1.0);
  const AtmosphereModel floor = with_layer(std::make_shared<IsotropicPhase>(), ForwardLobePhase::kFloor);
  const double sun = 50.0;
  std::vector<std::array<double, 3>> dirs;
  for (double t : {0.0, 30.0, 60.0, 75.0, 85.0, 88.0}) {
    for (double p : {0.0, 20.0, 45.0, 90.0, 135.0, 180.0}) {
      const std::array<double, 3> d = Dir(t, p);
      if (d[0] * std::sin(sun * kDeg) + d[2] * std::cos(sun * kDeg) < std::cos(15.0 * kDeg)) dirs.push_back(d);
    }
  }
  SkyMethodOptions o;
  o.quality = Quality::kMedium;
  const std::vector<double> clear = MethodY(sc, *MakeSkyMethod("orders", floor, o, {}), sun, dirs);
  auto rms_max = [&](const std::vector<double>& y, double* mx) {
    double ss = 0.0;
    *mx = 0.0;
    for (size_t d = 0; d < dirs.size(); ++d) {
      const double e = y[d] / clear[d] - 1.0;
      ss += e * e;
      *mx = std::max(*mx, std::abs(e));
    }
    return std::sqrt(ss / static_cast<double>(dirs.size()));
  };
  double mx = 0.0, mx0 = 0.0;
  const double rms = rms_max(MethodY(sc, *MakeSkyMethod("orders", with, o, {}), sun, dirs), &mx);
  o.table_size["ss_scaled"] = 0;
  const double rms0 = rms_max(MethodY(sc, *MakeSkyMethod("orders", with, o, {}), sun, dirs), &mx0);
  std::printf("a forward-only layer of tau 1, %zu directions: RMS %.2f %%, max %.2f %% (unscaled attenuation %.1f / %.1f %%)\n",
              dirs.size(), 100.0 * rms, 100.0 * mx, 100.0 * rms0, 100.0 * mx0);
  EXPECT_LT(mx, 0.01);
  EXPECT_GT(rms0, 0.2);
}
