// The path tracer's twilight estimators (transport/path_tracer.h: sun_guided_nee, twilight_guide,
// the majorant scale of segment NEE's transmittances; docs/sky-render.md "Deep twilight"): they
// change the sampling, not the expectation, and they lower the variance where the Earth's
// shadow covers the lower atmosphere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "method_scenes.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

struct Estimate {
  double mean = 0, stderr_ = 0;
};

// Y (cd/m^2) of `paths` fixed-count paths of ColorPath and its standard error.
Estimate Render(const PathTracer& pt, const glm::dvec3& pos, const glm::dvec3& dir, const glm::dvec3& sun, uint64_t stream,
                uint64_t paths) {
  double sum = 0, sum2 = 0;
  for (uint64_t n = 0; n < paths; ++n) {
    double xyz[3];
    pt.ColorPath(pos, dir, sun, stream, n, xyz);
    sum += xyz[1];
    sum2 += xyz[1] * xyz[1];
  }
  const double mean = sum / paths;
  return {mean, std::sqrt(std::max(0.0, sum2 / paths - mean * mean) / (paths - 1))};
}

PathTracerSettings Plain() {
  PathTracerSettings s;
  s.sun_guided_nee = false;
  s.twilight_guide = false;
  return s;
}

}  // namespace

// Unbiased: the guided and the plain segment NEE agree within 4 combined standard errors on the
// clear sky (21 wavelengths) with the sun 4 deg below the horizon, towards the sun, at the
// zenith and away from the sun (16 000 guided, 48 000 plain paths per direction; measured
// |z| <= 1.3).
TEST(PathTracerTwilight, GuidedAgreesWithThePlainEstimator) {
  const TestScene sc = LoadTestScene("clear");
  const PathTracer guided(sc.model, sc.weights, PathTracerSettings{});
  const PathTracer plain(sc.model, sc.weights, Plain());
  const glm::dvec3 pos(0, 0, sc.model.bottom_radius_m + 1.0), sun = DirectionFromAngles(94 * kDeg, 0.0);
  const double views[][2] = {{85, 0}, {0, 0}, {60, 180}};
  for (size_t v = 0; v < std::size(views); ++v) {
    const glm::dvec3 d = DirectionFromAngles(views[v][0] * kDeg, views[v][1] * kDeg);
    const Estimate g = Render(guided, pos, d, sun, 10 + v, 16000);
    const Estimate p = Render(plain, pos, d, sun, 20 + v, 48000);
    const double z = (g.mean - p.mean) / std::hypot(g.stderr_, p.stderr_);
    std::printf("sun -4 deg, view %.0f/%.0f: guided %.5g +- %.2f %%, plain %.5g +- %.2f %%, z %.2f\n", views[v][0], views[v][1],
                g.mean, 100 * g.stderr_ / g.mean, p.mean, 100 * p.stderr_ / p.mean, z);
    EXPECT_LT(std::abs(z), 4.0) << "view " << v;
  }
}

// Variance reduction: 8 deg below the horizon, at the zenith and away from the sun, the guided
// estimator's relative standard error at equal path count is at most 0.7 x the plain one's
// (measured 0.29 and 0.44 with 16 000 paths; the sunlit air is seen from the shadowed lower
// atmosphere through a narrow band of directions and through long grazing sun rays).
TEST(PathTracerTwilight, GuidedLowersTheVarianceInDeepTwilight) {
  const TestScene sc = LoadTestScene("clear");
  const PathTracer guided(sc.model, sc.weights, PathTracerSettings{});
  const PathTracer plain(sc.model, sc.weights, Plain());
  const glm::dvec3 pos(0, 0, sc.model.bottom_radius_m + 1.0), sun = DirectionFromAngles(98 * kDeg, 0.0);
  const double views[][2] = {{0, 0}, {60, 180}};
  for (size_t v = 0; v < std::size(views); ++v) {
    const glm::dvec3 d = DirectionFromAngles(views[v][0] * kDeg, views[v][1] * kDeg);
    const Estimate g = Render(guided, pos, d, sun, 30 + v, 16000);
    const Estimate p = Render(plain, pos, d, sun, 30 + v, 16000);
    std::printf("sun -8 deg, view %.0f/%.0f: guided %.5g +- %.2f %%, plain %.5g +- %.2f %%\n", views[v][0], views[v][1], g.mean,
                100 * g.stderr_ / g.mean, p.mean, 100 * p.stderr_ / p.mean);
    EXPECT_LT(g.stderr_ / g.mean, 0.7 * p.stderr_ / p.mean) << "view " << v;
  }
}
