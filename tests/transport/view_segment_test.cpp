// View segments (transport/view_segment.h): the geometry, the transmittance, the path tracer's
// segment estimator against a closed form, and `orders` against the path tracer.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "io/error.h"
#include "method_scenes.h"
#include "transport/path_tracer.h"
#include "transport/sky_method.h"
#include "transport/view_segment.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

// Single scattering of a homogeneous plane-parallel slab (thickness H, extinction sigma,
// scattering sigma_s, phase value P, collimated irradiance E along mu_s at the top) seen from
// the bottom along mu_v > 0, counting only the first d metres of the view ray:
//   L = E P sigma_s exp(-sigma H / mu_s) int_0^d exp(-sigma s (1 - mu_v / mu_s)) ds.
double SlabSegment(double E, double P, double sigma_s, double sigma, double H, double mu_v, double mu_s, double d) {
  const double k = sigma * (1.0 - mu_v / mu_s);
  const double integral = std::abs(k) < 1e-15 ? d : (1.0 - std::exp(-k * d)) / k;
  return E * P * sigma_s * std::exp(-sigma * H / mu_s) * integral;
}

}  // namespace

TEST(ViewSegment, EndGeometry) {
  const AtmosphereModel m = Homogeneous(6371e3, 100e3, {1e-5}, {0.0}, std::make_shared<IsotropicPhase>(), 0.0);
  const double R = m.bottom_radius_m;
  ViewSegment seg;
  seg.max_altitude_m = 2000.0;
  EXPECT_NEAR(SegmentEnd(m, 0.0, 1.0, seg), 2000.0, 1e-6);
  // Horizontal from the ground: the chord to the cut sphere, sqrt((R + h)^2 - R^2).
  EXPECT_NEAR(SegmentEnd(m, 0.0, 0.0, seg), std::sqrt((R + 2000.0) * (R + 2000.0) - R * R), 1e-3);
  // Downward from 500 m at 30 deg below the horizon: the ground.
  const double r = R + 500.0, mu = -0.5;
  const double t_ground = -r * mu - std::sqrt(r * r * (mu * mu - 1.0) + R * R);
  EXPECT_NEAR(SegmentEnd(m, 500.0, mu, seg), t_ground, 1e-6);
  seg.max_distance_m = 300.0;
  EXPECT_DOUBLE_EQ(SegmentEnd(m, 500.0, mu, seg), 300.0);
  // No limits: the top of the atmosphere.
  EXPECT_NEAR(SegmentEnd(m, 0.0, 1.0, ViewSegment{}), 100e3, 1e-6);
  // An observer above the cut is a usage error.
  ViewSegment low;
  low.max_altitude_m = 100.0;
  EXPECT_THROW(SegmentEnd(m, 500.0, 1.0, low), UsageError);
}

TEST(ViewSegment, TransmittanceIsExact) {
  // Homogeneous: exp(-sigma t) whatever the path's shape.
  const AtmosphereModel h = Homogeneous(6371e3, 20e3, {1e-5, 4e-5}, {2e-6, 0.0}, std::make_shared<IsotropicPhase>(), 0.0);
  std::vector<double> T;
  for (double mu : {1.0, 0.3, 0.0, -0.2}) {
    for (double t : {10.0, 1500.0, 40e3}) {
      const double tt = std::min(t, SegmentEnd(h, 100.0, mu, ViewSegment{}));
      SegmentTransmittance(h, 100.0, mu, tt, &T);
      EXPECT_NEAR(T[0], std::exp(-1.2e-5 * tt), 1e-9) << mu << " " << t;
      EXPECT_NEAR(T[1], std::exp(-4e-5 * tt), 1e-9) << mu << " " << t;
    }
  }
  // Vertical through the clear atmosphere: the exact vertical optical depth.
  const TestScene sc = LoadTestScene("clear", {.aerosols = false});
  SegmentTransmittance(sc.model, 0.0, 1.0, 15e3, &T);
  for (size_t w = 0; w < sc.model.wavelengths(); w += 5) {
    EXPECT_NEAR(-std::log(T[w]), sc.model.VerticalOpticalDepth(0.0, 15e3, w), 1e-5 * sc.model.VerticalOpticalDepth(0.0, 15e3, w));
  }
}

// The path tracer's segment estimator on a flat absorbing slab (orders >= 2 are ~1e-3 of the
// signal): within 4 standard errors + 3e-3 of the closed form for short, long and sloping
// segments; the shadowed variant (no order 1) is ~1e-3 of it.
TEST(ViewSegment, PathTracerMatchesSlabClosedForm) {
  const double R = 1e12, H = 10000.0, sigma = 0.5 / H, w0 = 1e-3;
  const AtmosphereModel m =
      Homogeneous(R, H, {w0 * sigma}, {(1 - w0) * sigma}, std::make_shared<IsotropicPhase>(), 0.0);
  PathTracer pt(m, {{1.0, 1.0, 1.0}}, PathTracerSettings{});
  const glm::dvec3 pos(0, 0, R + 1.0);
  const glm::dvec3 sun = DirectionFromAngles(40.0 * kDeg, 0.0);
  uint64_t stream = 1;
  for (double theta_v : {0.0, 60.0}) {
    for (double d : {50.0, 2000.0, 1e9}) {
      const glm::dvec3 view = DirectionFromAngles(theta_v * kDeg, 2.0);
      const double t_end = std::min(d, (H - 1.0) / std::cos(theta_v * kDeg));
      const ColorEstimate e = pt.SegmentRadiance(pos, view, sun, t_end, stream++);
      const double expected =
          SlabSegment(1.0, 1.0 / (4 * kPi), w0 * sigma, sigma, H, std::cos(theta_v * kDeg), std::cos(40.0 * kDeg), t_end);
      EXPECT_NEAR(e.xyz[1], expected, 4 * e.xyz_stderr[1] + 3e-3 * expected) << theta_v << " " << d;
      const ColorEstimate shadowed = pt.SegmentRadiance(pos, view, sun, t_end, stream++, false);
      EXPECT_LT(shadowed.xyz[1], 5e-3 * expected) << theta_v << " " << d;
    }
  }
}

// `orders` against the path tracer on the clear sky (21 wavelengths), sun 30 deg above the
// horizon, a 2 km cut: segments of 100 m, 1 km and the whole low atmosphere. The bound, 6 %,
// is the measured `orders` error of these directions (up to -4.8 % on 48 wavelengths, docs/
// sky-methods.md) plus 2 reference standard errors. The shadowed segment must be the full
// segment minus `orders`' own single scattering.
TEST(ViewSegment, OrdersAgreesWithPathTracer) {
  const TestScene sc = LoadTestScene("clear");
  SkyMethodOptions o;
  o.quality = Quality::kLow;
  o.segments = true;
  const std::unique_ptr<SkyMethod> orders = MakeSkyMethod("orders", sc.model, o, {});
  ASSERT_TRUE(orders->SupportsSegments());
  PathTracerSettings ps;
  ps.target_relative_error = 0.02;
  ps.min_paths = 256;
  PathTracer pt(sc.model, sc.weights, ps);
  const double ts = 60.0 * kDeg;
  const glm::dvec3 sun = DirectionFromAngles(ts, 0.0);
  const std::vector<std::array<double, 3>> dirs = {Dir(10, 90), Dir(80, 0), Dir(85, 180), Dir(90, 90)};
  uint64_t stream = 100;
  for (double d : {100.0, 1000.0, 1e9}) {
    ViewSegment seg;
    seg.max_distance_m = d;
    seg.max_altitude_m = 2000.0;
    std::vector<double> L, Ls;
    orders->SegmentRadiance(0.0, ts, dirs, seg, &L);
    ViewSegment shadowed = seg;
    shadowed.single_scattering = false;
    orders->SegmentRadiance(0.0, ts, dirs, shadowed, &Ls);
    const size_t nw = sc.model.wavelengths();
    for (size_t i = 0; i < dirs.size(); ++i) {
      const glm::dvec3 v(dirs[i][0], dirs[i][1], dirs[i][2]);
      const double t_end = SegmentEnd(sc.model, 0.0, v.z, seg);
      const ColorEstimate e = pt.SegmentRadiance(glm::dvec3(0, 0, sc.model.bottom_radius_m), v, sun, t_end, stream++);
      const double y = sc.Y(&L[i * nw]);
      EXPECT_NEAR(y, e.xyz[1], 0.06 * e.xyz[1] + 2 * e.xyz_stderr[1]) << "d " << d << " dir " << i;
      // Shadowed fog: below the full fog, and of the size of multiple scattering (the path
      // tracer's shadowed estimate). Not compared 20 deg from the sun (dir 1): there `orders`'
      // multiple scattering comes from a delta-scaled medium whose truncated forward peak
      // (15 deg) moves true order-2 light into the unscattered beam: the total is right (above)
      // but the split between order 1 and the rest is not (measured -19 %, docs/fog.md).
      const double ys = sc.Y(&Ls[i * nw]);
      EXPECT_LT(ys, y) << "d " << d << " dir " << i;
      if (i == 1) continue;
      const ColorEstimate es =
          pt.SegmentRadiance(glm::dvec3(0, 0, sc.model.bottom_radius_m), v, sun, t_end, stream++, false);
      EXPECT_NEAR(ys, es.xyz[1], 0.12 * es.xyz[1] + 2 * es.xyz_stderr[1]) << "shadowed d " << d << " dir " << i;
    }
  }
}

// With no limits, a segment looking up is the whole sky ray: `orders` integrating its tabulated
// multiple-scattering source along the view ray must agree with its own sky radiance (the
// multiple-scattering table interpolated at the observer) to 0.5 % (2 % two degrees above the
// horizon).
TEST(ViewSegment, OrdersUnlimitedSegmentIsTheSky) {
  const TestScene sc = LoadTestScene("clear");
  SkyMethodOptions o;
  o.quality = Quality::kLow;
  o.segments = true;
  const std::unique_ptr<SkyMethod> orders = MakeSkyMethod("orders", sc.model, o, {});
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(45, 90), Dir(80, 0), Dir(80, 180), Dir(88, 90)};
  for (double sun_deg : {30.0, 80.0}) {
    std::vector<double> L, Ls;
    orders->Radiance(0.0, sun_deg * kDeg, dirs, &L);
    orders->SegmentRadiance(0.0, sun_deg * kDeg, dirs, ViewSegment{}, &Ls);
    const size_t nw = sc.model.wavelengths();
    for (size_t i = 0; i < dirs.size(); ++i) {
      // 2 deg above the horizon the table's interpolation in view angle differs from the
      // march through the source by up to 1.1 % (measured at quality low); since the table rays
      // weight their steps by the single-scattering albedo (energy-conserving) and
      // the march by the point's sigma_s*, up to 2.1 % there and 0.55 % 45 deg up (sun 80 deg).
      const double tol = i == 4 ? 0.025 : 7e-3;
      EXPECT_NEAR(sc.Y(&Ls[i * nw]), sc.Y(&L[i * nw]), tol * sc.Y(&L[i * nw])) << sun_deg << " dir " << i;
    }
  }
}

// Methods without segment support say so.
TEST(ViewSegment, OtherMethodsRefuse) {
  const AtmosphereModel m = Homogeneous(6371e3, 100e3, {1e-5}, {0.0}, std::make_shared<IsotropicPhase>(), 0.0);
  const std::unique_ptr<SkyMethod> single = MakeSkyMethod("single", m, SkyMethodOptions{}, {});
  EXPECT_FALSE(single->SupportsSegments());
  std::vector<double> out;
  EXPECT_THROW(single->SegmentRadiance(0.0, 0.5, {Dir(0, 0)}, ViewSegment{}, &out), UsageError);
}

// orders keeps the sources that segments need only when asked (SkyMethodOptions::segments): the
// sky is the same bytes without them, and a segment is refused.
TEST(ViewSegment, OrdersWithoutSegmentsIsTheSameSky) {
  const TestScene sc = LoadTestScene("cloudy1");
  SkyMethodOptions o;
  o.quality = Quality::kLow;
  const std::unique_ptr<SkyMethod> sky = MakeSkyMethod("orders", sc.model, o, {});
  o.segments = true;
  const std::unique_ptr<SkyMethod> with = MakeSkyMethod("orders", sc.model, o, {});
  EXPECT_FALSE(sky->SupportsSegments());
  EXPECT_TRUE(with->SupportsSegments());
  const std::vector<std::array<double, 3>> dirs = {Dir(0, 0), Dir(60, 90), Dir(88, 180), Dir(95, 30)};
  for (double sun_deg : {30.0, 92.0}) {
    std::vector<double> a, b;
    sky->Radiance(0.0, sun_deg * kDeg, dirs, &a);
    with->Radiance(0.0, sun_deg * kDeg, dirs, &b);
    EXPECT_EQ(a, b) << sun_deg;
  }
  std::vector<double> out;
  EXPECT_THROW(sky->SegmentRadiance(0.0, 0.5, dirs, ViewSegment{}, &out), std::logic_error);
}
