// sky-render points (transport/points.h): the deterministic methods at explicit geometries are
// their render's numbers; the path tracer's points agree with `orders` within the figures of
// docs/sky-methods.md; every output wavelength's error bar covers its true value as a 95 %
// interval should (the wavelength MIS of transport/path_tracer.h); rows do not depend on their
// position in the file nor on the thread count.
#include <gtest/gtest.h>

#include <cmath>

#include "lut/directions.h"
#include "method_scenes.h"
#include "support/log.h"
#include "support/threads.h"
#include "transport/points.h"
#include "transport/sky_render.h"

namespace skybake {
namespace {

using testing::kDeg;
using testing::LoadTestScene;
using testing::TestScene;

// A Scene around a test model (points reads the model, the colour weights and the tracer's
// settings only).
Scene SceneOf(const TestScene& t) {
  Scene s;
  s.model = t.model;
  s.xyz_weights = t.weights;
  s.spec.observer_altitude_m = 0.0;
  return s;
}

PointsInput InputOf(const std::vector<PointGeometry>& rows, const std::vector<size_t>& wl) {
  PointsInput in;
  in.rows = rows;
  in.wavelengths = wl;
  return in;
}

// `points --method orders` at the texel directions of a render is the render (the same view ray
// through the same tables: the texel's float Y to float rounding).
TEST(Points, OrdersAtTexelCentresAreTheRender) {
  testing::SceneOptions so;
  so.step_nm = 40.0;
  const TestScene t = LoadTestScene("clear", so);
  const Scene scene = SceneOf(t);
  SkyMethodOptions mo;
  mo.quality = Quality::kLow;
  const std::unique_ptr<SkyMethod> method = MakeSkyMethod("orders", scene.model, mo, nullptr);
  SkyRenderSettings rs;
  rs.mapping = MakeSkyMapping("equirectangular", 16, 8);
  rs.sun_zenith_deg = {30.0, 85.0};
  rs.ambient = false;
  rs.transmittance_angles = 2;
  const SkyRenderResult sky = RenderSkyDeterministic(*method, scene.model, scene.xyz_weights, rs, nullptr);
  std::vector<PointGeometry> rows;
  std::vector<float> expected;
  for (size_t si = 0; si < rs.sun_zenith_deg.size(); ++si) {
    for (int y = 0; y < 8; ++y) {
      for (int x = 0; x < 16; ++x) {
        const std::array<double, 3> d = *rs.mapping->TexelDirection(x, y, rs.sun_zenith_deg[si] * kDeg);
        rows.push_back({rs.sun_zenith_deg[si], std::acos(std::clamp(d[2], -1.0, 1.0)) / kDeg,
                        std::atan2(d[1], d[0]) / kDeg, 0.0});
        expected.push_back(sky.slices[si].xyz[static_cast<size_t>(y * 16 + x) * 3 + 1]);
      }
    }
  }
  PointsOptions po;
  po.method = "orders";
  po.method_options = mo;
  const PointsResult res = EvaluatePoints(scene, po, InputOf(rows, {1, 4, 7}), nullptr);
  EXPECT_EQ(res.methods_built, 1u);
  ASSERT_TRUE(res.has_single);
  double worst = 0.0;
  for (size_t r = 0; r < rows.size(); ++r) {
    const double rel = std::abs(static_cast<float>(res.rows[r].y_cd_m2) - expected[r]) / expected[r];
    worst = std::max(worst, rel);
    EXPECT_LE(rel, 3e-7) << "row " << r << ": points " << res.rows[r].y_cd_m2 << " render " << expected[r];
    for (size_t j = 0; j < 3; ++j) {
      EXPECT_GT(res.rows[r].single[j], 0.0);
      EXPECT_LE(res.rows[r].single[j], res.rows[r].radiance[j] * (1.0 + 1e-6));  // L_1 is part of L
    }
  }
  SKYBAKE_LOG("orders points vs render texels: %zu texels, largest |dY|/Y %.2e\n", rows.size(), worst);
}

// The path tracer's points against `orders` low at the same geometries: within the figures of
// docs/sky-methods.md ("Speed and accuracy": orders low on the clear sky, max 3-4 % in Y over
// the sky at sun elevations 60/20/5 deg) plus 3 standard errors. Spectral columns get the same
// bound (the method's error is spectrally smooth; its Y is a weighted sum of them).
TEST(Points, PathAgreesWithOrdersWithinTheDocumentedFigures) {
  testing::SceneOptions so;
  so.step_nm = 40.0;
  const TestScene t = LoadTestScene("clear", so);
  Scene scene = SceneOf(t);
  scene.tracer.target_relative_error = 0.015;
  scene.tracer.min_paths = 512;
  const std::vector<PointGeometry> rows = {{30, 0, 0, 0},   {30, 60, 0, 0},  {30, 80, 180, 0},
                                           {70, 45, 90, 0}, {70, 85, 30, 0}, {85, 30, 180, 0}};
  const std::vector<size_t> wl = {1, 4, 7};  // 420, 540, 660 nm
  PointsOptions pp;
  const PointsResult path = EvaluatePoints(scene, pp, InputOf(rows, wl), nullptr);
  PointsOptions po;
  po.method = "orders";
  po.method_options.quality = Quality::kLow;
  const PointsResult orders = EvaluatePoints(scene, po, InputOf(rows, wl), nullptr);
  for (size_t r = 0; r < rows.size(); ++r) {
    const PointResult &a = path.rows[r], &b = orders.rows[r];
    const double dy = b.y_cd_m2 / a.y_cd_m2 - 1.0;
    SKYBAKE_LOG("sun %g view %g az %g: Y orders/path - 1 = %+.2f %% (path %.2f %%, %llu paths);", rows[r].sun_zenith_deg,
                rows[r].view_zenith_deg, rows[r].relative_azimuth_deg, 100 * dy, 100 * a.y_stderr_cd_m2 / a.y_cd_m2,
                static_cast<unsigned long long>(a.paths));
    EXPECT_LE(std::abs(b.y_cd_m2 - a.y_cd_m2), 0.04 * a.y_cd_m2 + 3.0 * a.y_stderr_cd_m2) << "row " << r;
    for (size_t j = 0; j < wl.size(); ++j) {
      SKYBAKE_LOG(" %+.2f", 100 * (b.radiance[j] / a.radiance[j] - 1.0));
      EXPECT_LE(std::abs(b.radiance[j] - a.radiance[j]), 0.04 * a.radiance[j] + 3.0 * a.radiance_stderr[j]) << "row " << r;
      EXPECT_LE(a.radiance_stderr[j], 0.015 * a.radiance[j]) << "the stopping rule covers the spectral columns";
      EXPECT_EQ(a.sun_transmittance[j], b.sun_transmittance[j]);
    }
    SKYBAKE_LOG(" %%\n");
  }
}

// Coverage of the error bars per wavelength: 150 independent seeds of 256 paths at a low sun
// towards the horizon (where the attenuation of one wavelength differs most from another's) and
// 3 deg below the sun (the aerosol's forward peak), each |estimate - reference| <
// 1.96 sqrt(sigma^2 + sigma_ref^2) against a reference of 2^16 paths with its own seed. An honest
// 95 % interval covers in 95 % of the trials; with 150 trials the binomial standard deviation of
// the fraction is 1.8 %, so the bound is [0.88, 0.99] (95 % - 4 sd, + 2 sd) per wavelength.
// At these path counts the bound does not separate the wavelength MIS from the hero-first
// estimator (wavelength_mis = false): both stay inside it.
TEST(Points, ErrorBarsCoverEveryWavelength) {
  testing::SceneOptions so;
  so.step_nm = 40.0;
  const TestScene t = LoadTestScene("clear", so);
  Scene scene = SceneOf(t);
  const std::vector<PointGeometry> rows = {{80, 84, 0, 0}, {60, 57, 0, 0}};
  const std::vector<size_t> wl = {1, 4, 7};  // 420, 540, 660 nm: the first drives nothing now
  PointsOptions ref_o;
  ref_o.paths = 1u << 16;
  scene.tracer.seed = 1000003;
  const PointsResult ref = EvaluatePoints(scene, ref_o, InputOf(rows, wl), nullptr);
  PointsOptions o;
  o.paths = 256;
  constexpr int kTrials = 150;
  std::vector<int> inside(rows.size() * wl.size(), 0), inside_y(rows.size(), 0);
  for (int trial = 0; trial < kTrials; ++trial) {
    scene.tracer.seed = 7 + static_cast<uint64_t>(trial);
    const PointsResult res = EvaluatePoints(scene, o, InputOf(rows, wl), nullptr);
    for (size_t r = 0; r < rows.size(); ++r) {
      for (size_t j = 0; j < wl.size(); ++j) {
        const double s = std::hypot(res.rows[r].radiance_stderr[j], ref.rows[r].radiance_stderr[j]);
        if (std::abs(res.rows[r].radiance[j] - ref.rows[r].radiance[j]) < 1.96 * s) ++inside[r * wl.size() + j];
      }
      const double sy = std::hypot(res.rows[r].y_stderr_cd_m2, ref.rows[r].y_stderr_cd_m2);
      if (std::abs(res.rows[r].y_cd_m2 - ref.rows[r].y_cd_m2) < 1.96 * sy) ++inside_y[r];
    }
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    SKYBAKE_LOG("sun %g view %g: coverage", rows[r].sun_zenith_deg, rows[r].view_zenith_deg);
    for (size_t j = 0; j < wl.size(); ++j) {
      const double f = static_cast<double>(inside[r * wl.size() + j]) / kTrials;
      SKYBAKE_LOG(" %g nm %.3f", t.model.wavelength_nm[wl[j]], f);
      EXPECT_GE(f, 0.88) << "row " << r << " wavelength " << j;
      EXPECT_LE(f, 0.99) << "row " << r << " wavelength " << j;
    }
    const double fy = static_cast<double>(inside_y[r]) / kTrials;
    SKYBAKE_LOG(", Y %.3f\n", fy);
    EXPECT_GE(fy, 0.88);
    EXPECT_LE(fy, 0.99);
  }
}

// A row's numbers depend on its geometry and the seed only: the same geometry at another
// position of the file, or computed on one thread instead of two, gives the same bytes.
TEST(Points, RowsAreKeyedByGeometryNotPosition) {
  testing::SceneOptions so;
  so.step_nm = 40.0;
  so.aerosols = false;
  const TestScene t = LoadTestScene("clear", so);
  const Scene scene = SceneOf(t);
  PointsOptions o;
  o.paths = 256;
  const PointGeometry a{40, 50, 10, 0}, b{40, 70, 170, 0};
  const PointsResult ab = test::WithThreads(2, [&] { return EvaluatePoints(scene, o, InputOf({a, b}, {2, 5}), nullptr); });
  const PointsResult ba = test::WithThreads(1, [&] { return EvaluatePoints(scene, o, InputOf({b, a}, {2, 5}), nullptr); });
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(ab.rows[0].radiance[j], ba.rows[1].radiance[j]);
    EXPECT_EQ(ab.rows[0].radiance_stderr[j], ba.rows[1].radiance_stderr[j]);
    EXPECT_EQ(ab.rows[1].single[j], ba.rows[0].single[j]);
  }
  EXPECT_EQ(ab.rows[0].y_cd_m2, ba.rows[1].y_cd_m2);
  EXPECT_NE(ab.rows[0].radiance[0], ab.rows[1].radiance[0]);
  EXPECT_NE(PointStreamKey(a), PointStreamKey(b));
}

}  // namespace
}  // namespace skybake
