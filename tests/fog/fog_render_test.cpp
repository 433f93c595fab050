// The reference fog renders, the packed LUTs and the reference evaluator on a physical sky
// (fog/fog_render.h, fog/fog_luts.h, fog/fog_evaluator.h; GT7 sky talk,
// "Fog"). Laws:
//  - consistency: at infinite depth (the low-atmosphere boundary) the fog LUT, decoded by the
//    evaluator, equals a direct render (SkyMethod::SegmentRadiance) of the same restricted
//    atmosphere, at the LUT's nodes (packing only) and between them (mapping interpolation);
//    the depth tables' last column equals the LUT at the same sun angle and directions;
//  - the evaluator reproduces the LUT at its nodes, and the fog is 0 at depth 0;
//  - the shadowed fog is below the fog, and the occlusion blend is the talk's interpolation;
//  - the attenuation LUT against the exact transmittance (transport/view_segment.h);
//  - the model against the reference fog over directions x depths: the fitted depth function's
//    error, bounded by the measured figures (the model's own error; docs/fog.md);
//  - deterministic at any thread count; the path tracer agrees with `orders`.
// Scene: atmospheres/clear.yaml with its OPAC continental aerosol on 400-700 nm by 50 nm (7
// wavelengths, Mie table built here), CIE 1931 (OCIO's reference XYZ), `orders` at low quality,
// a 32 x 32 LUT (the product's size) on 5 slices (gt7-quadratic:3+2): small, so that the suite stays fast
// (about 32 s on one core, Release; 28 s of it the path-traced comparison).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include <glm/geometric.hpp>

#include "atmosphere/mie_optics.h"
#include "atmosphere/model_build.h"
#include "color/color.h"
#include "fog/fog_evaluator.h"
#include "fog/fog_luts.h"
#include "fog/fog_render.h"
#include "lut/gt7_mapping.h"
#include "optics/mie_table.h"
#include "optics/particle_type.h"
#include "optics/polydisperse.h"
#include "spectrum/cmf.h"
#include "spectrum/xyz.h"
#include "support/log.h"
#include "support/threads.h"
#include "transport/sky_scene.h"
#include "transport/view_segment.h"

using namespace skybake;
using namespace skybake::fog;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

Scene ClearScene() {
  Scene s;
  s.spec = LoadAtmosphere(SKYBAKE_SOURCE_DIR "/atmospheres/clear.yaml");
  s.spec.grid = GridSpec{100.0};
  s.profiles = ComputeProfiles(s.spec);
  s.grid = WavelengthGrid::Uniform(400, 700, 50);
  mie::ParticleType type = mie::LoadParticleType(*s.spec.aerosols[0].particle);
  mie::MieBuildOptions mo;
  mo.fits = false;
  auto table = std::make_shared<mie::MieTable>(mie::BuildMieTable(type, s.grid.wavelength_nm(), mo).table);
  std::vector<AerosolOptics> aerosols = {AerosolOpticsFromMie(s.spec.aerosols[0].name, table, s.grid)};
  s.model = BuildAtmosphereModel(s.spec, s.profiles, s.grid, aerosols, ModelOptions{}, nullptr);
  s.observer = Observer::kCie1931_2deg;
  XyzWeights w(s.grid, Cmf::LoadDefault(s.observer));
  for (size_t i = 0; i < s.grid.size(); ++i) s.xyz_weights.push_back({w.wx()[i], w.wy()[i], w.wz()[i]});
  s.tracer.target_relative_error = 0.03;
  s.tracer.min_paths = 256;
  return s;
}

FogRenderOptions SmallOptions() {
  FogRenderOptions o;
  o.method = "orders";
  o.method_options.quality = Quality::kLow;
  o.cut_altitude_m = 1000.0;  // the default cut (docs/fog.md, "The cut")
  o.lut_width = 32;
  o.lut_height = 32;
  o.time_mapping = "gt7-quadratic:3+2";  // slices at 0, 75.34, 90, 90, 100 deg (lut/gt7_mapping.h)
  o.elevations = 9;
  o.depths = 16;
  o.azimuth_deg = {0, 45, 90, 180};
  o.attenuation_width = 16;
  o.attenuation_height = 16;
  return o;
}

struct Fixture {
  Scene scene;
  FogRender render;
  FogProducts products;
  std::unique_ptr<FogEvaluator> eval;
  std::unique_ptr<SkyMethod> orders;
};

const Fixture& Clear() {
  static const Fixture* f = [] {
    auto* x = new Fixture;
    x->scene = ClearScene();
    FogRenderOptions o = SmallOptions();
    // Depth tables at two slice angles (29.6 deg and the horizon): the consistency test compares
    // them with the LUT at its own slices.
    const gt7::TimeMapping t = gt7::TimeMapping::FromName(o.time_mapping, x->scene.spec.planet->radius_m,
                                                          x->scene.spec.planet->top_m, x->scene.spec.observer_altitude_m);
    o.sun_zenith_deg = {t.SliceZenithDeg()[1], t.SliceZenithDeg()[2]};
    x->render = RenderFog(x->scene, o, {});
    const ColorConfig config = ColorConfig::Load();
    x->products = BuildFogProducts(x->render, "clear", FogFitOptions{}, config, nullptr);
    x->eval = std::make_unique<FogEvaluator>(MakeEvaluator(x->products));
    SkyMethodOptions mo = o.method_options;
    mo.observer_altitude_m = x->scene.spec.observer_altitude_m;
    mo.segments = true;
    x->orders = MakeSkyMethod("orders", x->scene.model, mo, {});
    return x;
  }();
  return *f;
}

// Direct render of the restricted atmosphere (cut at 1 km, infinite depth) in Linear Rec.2020.
std::vector<std::array<double, 3>> Direct(const Fixture& f, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                                          bool single = true) {
  ViewSegment seg;
  seg.max_altitude_m = f.render.cut_altitude_m;
  seg.single_scattering = single;
  std::vector<std::array<double, 3>> clamped;
  for (const auto& d : dirs) clamped.push_back(ClampToHorizon(d));
  std::vector<double> L;
  f.orders->SegmentRadiance(f.render.observer_altitude_m, sun_zenith_rad, clamped, seg, &L);
  const ColorConfig config = ColorConfig::Load();
  const ColorProcessor to2020 = config.Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  const size_t nw = f.scene.model.wavelengths();
  std::vector<std::array<double, 3>> out;
  for (size_t d = 0; d < dirs.size(); ++d) {
    std::array<float, 3> xyz{0, 0, 0};
    for (size_t w = 0; w < nw; ++w) {
      for (int c = 0; c < 3; ++c) xyz[c] += static_cast<float>(f.scene.xyz_weights[w][c] * L[d * nw + w]);
    }
    const std::array<float, 3> rgb = to2020.Apply(xyz);
    out.push_back({rgb[0], rgb[1], rgb[2]});
  }
  return out;
}

double Luma(const std::array<double, 3>& c) { return 0.2627 * c[0] + 0.678 * c[1] + 0.0593 * c[2]; }  // Rec.2020 Y row (ITU-R BT.2020)

}  // namespace

// At the LUT's nodes (texels, slice angles) the evaluator at infinite depth is the direct
// render of the restricted atmosphere up to R11G11B10F rounding: per channel <= 2^-7 (R, G) and
// 2^-6 (B) relative (docs/lut-pack.md, "Packing"). Measured: luminance 0.72 % at worst. Bound: the
// format's per-channel bounds, luminance 1 %.
TEST(FogRender, InfiniteDepthEqualsDirectRenderAtNodes) {
  const Fixture& f = Clear();
  const gt7::Gt7SkyMapping mapping = f.render.mapping();
  EXPECT_EQ(mapping.grid(), gt7::TexelGrid::kNodes);  // the fog's default (docs/fog.md, "Texel grid")
  double worst = 0.0;
  for (int k : {0, 1, 2, 4}) {
    const double ts = f.render.slice_zenith_deg[k] * kDeg;
    std::vector<std::array<double, 3>> dirs;
    for (int y = 0; y < f.render.lut_height; ++y) {
      for (int x = 0; x < f.render.lut_width; ++x) dirs.push_back(*mapping.TexelDirection(x, y, ts));
    }
    const auto direct = Direct(f, ts, dirs);
    for (size_t i = 0; i < dirs.size(); ++i) {
      const FogValue v = f.eval->Evaluate(dirs[i], 1e12, ts);
      EXPECT_EQ(v.x, 1.0);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(v.inscattered[c], direct[i][c], (c == 2 ? 0.0157 : 0.0079) * std::fabs(direct[i][c]) + 1e-9)
            << "slice " << k << " texel " << i << " channel " << c;
      }
      const double e = std::fabs(Luma(v.inscattered) / Luma(direct[i]) - 1.0);
      worst = std::max(worst, e);
    }
  }
  SKYBAKE_LOG("fog LUT at its nodes vs direct render: worst luminance error %.3f %%\n", 100 * worst);
  EXPECT_LT(worst, 0.01);
}

// Between the nodes (directions of an 18 x 7 grid over the upper hemisphere) at the slices' own
// sun angles: the evaluator at infinite depth vs the direct render, i.e. the GT7 sphere mapping's
// bilinear interpolation at 32 x 32 (the product's size) on the fog's node grid. Measured: sun 0
// deg (sun-aligned family) RMS 1.72 %, max 2.71 %; 75.34 deg (lat-long family) RMS 2.96 %, max
// 6.80 %. With lut-pack's texel centres the lat-long figures were RMS 11.7 %, max 60 %: the first
// row lay at view zenith 20 deg (v' = sqrt(2 K v - v^2), K = 0.42) and views above it were clamped
// to it, where the aerosol aureole makes the fog vary with azimuth (docs/fog.md, "Texel grid").
// Bounds: RMS 2 % / 4.5 %, max 5 % / 10 %.
TEST(FogRender, InfiniteDepthEqualsDirectRenderBetweenNodes) {
  const Fixture& f = Clear();
  for (double sza : {f.render.slice_zenith_deg[0], f.render.slice_zenith_deg[1]}) {
    const bool latlong = sza > 75.0;
    std::vector<std::array<double, 3>> dirs;
    for (int i = 0; i < 18; ++i) {
      for (double el : {0.5, 3.0, 10.0, 25.0, 45.0, 65.0, 85.0}) {
        const double a = (i + 0.5) * 10.0 * kDeg, e = el * kDeg;
        dirs.push_back({std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)});
      }
    }
    const auto direct = Direct(f, sza * kDeg, dirs);
    double sum2 = 0.0, worst = 0.0;
    size_t where = 0;
    for (size_t i = 0; i < dirs.size(); ++i) {
      const FogValue v = f.eval->Evaluate(dirs[i], 1e12, sza * kDeg);
      const double e = Luma(v.inscattered) / Luma(direct[i]) - 1.0;
      sum2 += e * e;
      if (std::fabs(e) > worst) {
        worst = std::fabs(e);
        where = i;
      }
    }
    SKYBAKE_LOG("  worst at direction (%.3f, %.3f, %.3f): %.4g vs direct %.4g\n", dirs[where][0], dirs[where][1], dirs[where][2],
                Luma(f.eval->Evaluate(dirs[where], 1e12, sza * kDeg).inscattered), Luma(direct[where]));
    const double rms = std::sqrt(sum2 / static_cast<double>(dirs.size()));
    SKYBAKE_LOG("fog LUT between nodes, sun %.2f deg: RMS %.2f %%, max %.2f %%\n", sza, 100 * rms, 100 * worst);
    EXPECT_LT(rms, latlong ? 0.045 : 0.02) << sza;
    EXPECT_LT(worst, latlong ? 0.10 : 0.05) << sza;
  }
}

// The depth tables' last column (x = 1: the whole segment) and the LUT slice at the same sun angle
// are two renders of the same quantity: equal up to the LUT's packing and direction interpolation
// (the tables' directions are not texel nodes). Tables at 75.34 deg (lat-long family, see above)
// and 90 deg. Measured: luminance RMS 1.77 %, max 8.6 % (the report's infinite_depth figures;
// 11.7 % and 76 % on texel centres, the zenith as above). Bounds: RMS 3 %, max 15 %.
TEST(FogRender, DepthTablesMatchTheLutAtInfiniteDepth) {
  const Fixture& f = Clear();
  const ErrorStats& s = f.products.fog_eval.infinite_depth;
  SKYBAKE_LOG("depth tables (x = 1) vs decoded LUT: RMS %.2f %%, max %.2f %% (%zu samples)\n", 100 * s.rms, 100 * s.max, s.count);
  EXPECT_GT(s.count, 0u);
  EXPECT_LT(s.rms, 0.03);
  EXPECT_LT(s.max, 0.15);
  // The fit's own x = 1 is exact by construction (F(1) = 1).
  EXPECT_EQ(f.products.fog_fit.infinite_depth.max, 0.0);
}

// Depth 0: no fog, transmittance 1 (to the packing's rounding of 1: R11G11B10F has 1 exactly).
TEST(FogRender, ZeroDepthGivesNoFog) {
  const Fixture& f = Clear();
  for (double el : {0.0, 10.0, 90.0}) {
    const FogValue v = f.eval->Evaluate({std::cos(el * kDeg), 0.0, std::sin(el * kDeg)}, 0.0, 40 * kDeg);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(v.inscattered[c], 0.0);
      EXPECT_NEAR(v.transmittance[c], 1.0, 1e-6);
    }
  }
}

// Shadowed fog (no single-scattered sun) is below the fog at every texel of every slice, and the
// occlusion o blends them as the talk does: (1 - o) Fog + o Shadowed, each with its own (a, p).
TEST(FogRender, ShadowedFogAndOcclusion) {
  const Fixture& f = Clear();
  size_t n = 0;
  for (size_t k = 0; k < f.render.slice_xyz.size(); ++k) {
    for (size_t t = 0; t < f.render.slice_xyz[k].size() / 3; ++t) {
      const float y = f.render.slice_xyz[k][t * 3 + 1], ys = f.render.slice_shadowed_xyz[k][t * 3 + 1];
      EXPECT_LE(ys, y * (1 + 1e-6)) << k << " " << t;
      EXPECT_GE(ys, 0.0f);
      ++n;
    }
  }
  EXPECT_GT(n, 0u);
  const std::array<double, 3> d{0.6, 0.3, std::sqrt(1 - 0.45)};
  const double ts = 50 * kDeg, depth = 800.0;
  const FogValue v0 = f.eval->Evaluate(d, depth, ts, 0.0), v1 = f.eval->Evaluate(d, depth, ts, 1.0),
                 vh = f.eval->Evaluate(d, depth, ts, 0.25);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(v1.inscattered[c], v0.inscattered[c]);
    EXPECT_NEAR(vh.inscattered[c], 0.75 * v0.inscattered[c] + 0.25 * v1.inscattered[c], 1e-12 * v0.inscattered[c]);
  }
}

// The attenuation LUT (64 x 64 in the product, 16 x 16 here) against the exact sunlight-weighted
// transmittance (SegmentTransmittance, [E0 T]_c / [E0]_c) at points between its nodes, and at its
// nodes. Nodes: packing only (<= 2^-7, 2^-6 relative; measured 0.0078 absolute at worst).
// Between nodes (u, v half-way): bilinear in u = x^(1/3), v = elevation^(1/2); measured here
// worst 0.039 absolute, RMS 0.0079. Bounds:
// 0.01 absolute at the nodes, 0.06 worst and 0.012 RMS between them.
TEST(FogRender, AttenuationMatchesExactTransmittance) {
  const Fixture& f = Clear();
  const ColorConfig config = ColorConfig::Load();
  const ColorProcessor to2020 = config.Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  const size_t nw = f.scene.model.wavelengths();
  auto sun_rgb = [&](const std::vector<double>* T) {
    std::array<float, 3> xyz{0, 0, 0};
    for (size_t w = 0; w < nw; ++w) {
      for (int c = 0; c < 3; ++c) xyz[c] += static_cast<float>(f.scene.xyz_weights[w][c] * f.scene.model.sun.irradiance[w] * (T ? (*T)[w] : 1.0));
    }
    return to2020.Apply(xyz);
  };
  const std::array<float, 3> e0 = sun_rgb(nullptr);
  const FogGeometry g = f.render.geometry();
  const int W = f.render.attenuation_width, H = f.render.attenuation_height;
  double worst_node = 0.0, worst_mid = 0.0, sum2 = 0.0;
  size_t n = 0;
  for (int half = 0; half < 2; ++half) {
    for (int j = 0; j < H - half; ++j) {
      for (int i = 0; i < W - half; ++i) {
        const double u = (i + 0.5 * half) / (W - 1), v = (j + 0.5 * half) / (H - 1);
        const double mu = MuOfV(v), x = DepthOfU(u);
        std::vector<double> T;
        SegmentTransmittance(f.scene.model, f.render.observer_altitude_m, mu, x * g.BoundaryDistanceM(mu), &T);
        const std::array<float, 3> t = sun_rgb(&T);
        const std::array<double, 3> dir{std::sqrt(1 - mu * mu), 0.0, mu};
        const FogValue fv = f.eval->Evaluate(dir, x * g.BoundaryDistanceM(mu), 0.0);
        for (int c = 0; c < 3; ++c) {
          const double e = std::fabs(fv.transmittance[c] - t[c] / e0[c]);
          if (half) {
            worst_mid = std::max(worst_mid, e);
            sum2 += e * e;
            ++n;
          } else {
            worst_node = std::max(worst_node, e);
          }
        }
      }
    }
  }
  const double rms = std::sqrt(sum2 / static_cast<double>(n));
  SKYBAKE_LOG("attenuation LUT vs exact: nodes worst %.4f; half-way worst %.4f, RMS %.4f (absolute)\n", worst_node, worst_mid, rms);
  EXPECT_LT(worst_node, 0.01);
  EXPECT_LT(worst_mid, 0.06);
  EXPECT_LT(rms, 0.012);
}

// The fitted depth function against the reference fog over every direction x depth of the depth
// tables (sun 75.34 deg and 90 deg; cut 1 km), with the default parameters (per slice and
// elevation, docs/fog.md "Where a and p live"). Measured here (clear, orders low, 7 wavelengths):
// all RMS 6.92 %, max 60 %; near the camera (depth <= 1 km) RMS 5.39 %; horizon (elevation <= 1
// deg) RMS 17.0 % (the talk's global pair: all 9.94 %, near 8.90 %, the next test; its error is
// how the share of the fog near the camera changes with the elevation, which theta^p cannot
// follow). Bounds: RMS 8 % (all), 6.5 % (near the camera), 20 % (horizon), max 70 %. The evaluator
// on the packed LUTs adds the LUT's interpolation: measured RMS 7.40 % (all), 5.84 % (near the
// camera), bounds 9 % and 7 %.
TEST(FogRender, ModelErrorAgainstReference) {
  const Fixture& f = Clear();
  const FogProducts& p = f.products;
  SKYBAKE_LOG("fit: all RMS %.2f %% max %.1f %%; near RMS %.2f %% max %.1f %%; horizon RMS %.2f %% max %.1f %%\n",
              100 * p.fog_fit.all.rms, 100 * p.fog_fit.all.max, 100 * p.fog_fit.near.rms, 100 * p.fog_fit.near.max,
              100 * p.fog_fit.horizon.rms, 100 * p.fog_fit.horizon.max);
  SKYBAKE_LOG("evaluator: all RMS %.2f %%; near RMS %.2f %%; horizon RMS %.2f %%\n", 100 * p.fog_eval.all.rms,
              100 * p.fog_eval.near.rms, 100 * p.fog_eval.horizon.rms);
  SKYBAKE_LOG("fit a = %.4g %.4g %.4g, p = %.4g %.4g %.4g\n", p.params.a[0], p.params.a[1], p.params.a[2], p.params.p[0],
              p.params.p[1], p.params.p[2]);
  EXPECT_LT(p.fog_fit.all.rms, 0.08);
  EXPECT_LT(p.fog_fit.near.rms, 0.065);
  EXPECT_LT(p.fog_fit.horizon.rms, 0.20);
  EXPECT_LT(p.fog_fit.all.max, 0.70);
  EXPECT_LT(p.fog_eval.all.rms, 0.09);
  EXPECT_LT(p.fog_eval.near.rms, 0.07);
  for (const FitResult& r : p.fit_fog) {
    EXPECT_TRUE(std::isfinite(r.a) && std::isfinite(r.p));
    EXPECT_FALSE(r.fallback) << r.status;
    EXPECT_FALSE(r.at_bound) << r.status;
  }
}

// Per-slice parameters (docs/fog.md, "Where a and p live"): the fixture's two depth tables are at
// the sun zenith angles of slices 1 and 2, so slices 0 and 1 carry table 1's own fit, slices 2 to 4
// table 2's (constant beyond the first and the last table), and the evaluator blends rows i and
// i + 1 with the LUT's slice weight (linear in the sun angle), the last row beyond the last slice.
// Global parameters (--params global) are the talk's model: one pair.
TEST(FogRender, PerSliceParametersFollowTheSlices) {
  const Fixture& f = Clear();
  FogFitOptions so;
  so.params = ParamMode::kPerSlice;
  const FogProducts ps = BuildFogProducts(f.render, "clear", so, ColorConfig::Load(), nullptr);
  const FogEvaluator se = MakeEvaluator(ps);
  const FogParams& p = ps.params;
  ASSERT_EQ(p.slices.size(), f.render.slice_zenith_deg.size());
  EXPECT_TRUE(p.node_v.empty());
  for (size_t c = 0; c < 3; ++c) {
    for (size_t k : {0, 1}) {
      EXPECT_NEAR(p.slices[k].a[c], ps.table_fit_fog[0][c].a, 1e-12 * ps.table_fit_fog[0][c].a) << k;
      EXPECT_NEAR(p.slices[k].p[c], ps.table_fit_fog[0][c].p, 1e-12) << k;
      EXPECT_NEAR(p.slices[k].a_shadowed[c], ps.table_fit_shadowed[0][c].a, 1e-12 * ps.table_fit_shadowed[0][c].a);
    }
    for (size_t k : {2, 3, 4}) EXPECT_NEAR(p.slices[k].p[c], ps.table_fit_fog[1][c].p, 1e-12) << k;
  }
  // Between slices 1 (75.34 deg) and 2 (90 deg): the LUT's weight t, linear in the sun angle.
  const double z1 = f.render.slice_zenith_deg[1], z2 = f.render.slice_zenith_deg[2], z = 0.25 * z1 + 0.75 * z2;
  const FogParams::Slice q = se.ParamsAt(z * kDeg);
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(q.a[c], 0.25 * p.slices[1].a[c] + 0.75 * p.slices[2].a[c], 1e-9 * q.a[c]);
    EXPECT_NEAR(q.p[c], 0.25 * p.slices[1].p[c] + 0.75 * p.slices[2].p[c], 1e-9);
  }
  EXPECT_EQ(se.ParamsAt(105 * kDeg).a, p.slices.back().a);
  // The sun angle matters: the two tables' fits differ.
  EXPECT_GT(std::fabs(ps.table_fit_fog[0][1].p - ps.table_fit_fog[1][1].p), 0.01);
  // Measured: near the camera 8.08 % vs the global pair's 8.90 %, all 8.77 % vs 9.94 %.
  const FitDiagnostic& global = ps.diagnostics[0];
  ASSERT_EQ(global.name, "global");
  SKYBAKE_LOG("per-slice fit near camera RMS %.2f %% vs global %.2f %%; all %.2f %% vs %.2f %%\n", 100 * ps.fog_fit.near.rms,
              100 * global.near.rms, 100 * ps.fog_fit.all.rms, 100 * global.all.rms);
  EXPECT_LE(ps.fog_fit.all.rms, global.all.rms * (1 + 1e-9));
  // The global mode: no per-slice rows, the same (a, p) at every sun angle.
  FogFitOptions go;
  go.params = ParamMode::kGlobal;
  const FogProducts g = BuildFogProducts(f.render, "clear", go, ColorConfig::Load(), nullptr);
  EXPECT_TRUE(g.params.slices.empty());
  const FogEvaluator ge = MakeEvaluator(g);
  EXPECT_EQ(ge.ParamsAt(10 * kDeg).p, ge.ParamsAt(95 * kDeg).p);
  EXPECT_EQ(ge.ParamsAt(10 * kDeg).a, g.params.a);
  EXPECT_NEAR(g.fog_fit.all.rms, global.all.rms, 1e-12);
}

// Per slice and elevation (the default): a at the depth tables' elevations (nodes at v =
// (elevation/90 deg)^(1/2)), linear in v between them, clamped beyond; p per slice. At a node it is
// the table's k fitted on that elevation alone, divided by theta^p, so a theta^p is that k.
TEST(FogRender, PerSliceElevationParametersFollowTheNodes) {
  const Fixture& f = Clear();
  const FogParams& p = f.products.params;
  ASSERT_EQ(p.node_v.size(), f.render.elevation_deg.size());
  ASSERT_EQ(p.slices.size(), f.render.slice_zenith_deg.size());
  const double ts = f.render.slice_zenith_deg[1] * kDeg;  // table 1's sun angle: slice 1's row is its fit
  for (size_t j = 0; j < p.node_v.size(); ++j) {
    const double mu = std::sin(f.render.elevation_deg[j] * kDeg);
    EXPECT_NEAR(p.node_v[j], AttenuationV(mu), 1e-12);
    const FogParams::Slice q = f.eval->ParamsAt(ts, mu);
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(q.a[c], p.slices[1].a_nodes[j][c], 1e-9 * q.a[c]) << j;
    if (j + 1 < p.node_v.size()) {
      // Half-way in v between nodes j and j + 1: the mean of the two.
      const double v = 0.5 * (p.node_v[j] + p.node_v[j + 1]);
      const double mid_mu = std::sin(v * v * kPi / 2);
      const FogParams::Slice m = f.eval->ParamsAt(ts, mid_mu);
      for (size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(m.a[c], 0.5 * (p.slices[1].a_nodes[j][c] + p.slices[1].a_nodes[j + 1][c]), 1e-6 * m.a[c]) << j;
      }
    }
  }
  // Below the horizon: the horizon's node.
  EXPECT_EQ(f.eval->ParamsAt(ts, -0.3).a, f.eval->ParamsAt(ts, 0.0).a);
  // Over the tables, the elevation nodes take most of the depth function's error away (fit near
  // the camera below the per-slice model's; measured below in ModelErrorAgainstReference).
  const FitDiagnostic& global = f.products.diagnostics[0];
  EXPECT_LT(f.products.fog_fit.near.rms, global.near.rms);
}

// The same render at 1 and 2 threads: the same floats (work split by output element).
TEST(FogRender, DeterministicAcrossThreads) {
  const Fixture& f = Clear();
  FogRenderOptions o = SmallOptions();
  o.lut_width = o.lut_height = 4;
  o.sun_zenith_deg = {60};
  const FogRender a = test::WithThreads(1, [&] { return RenderFog(f.scene, o, {}); });
  const FogRender b = test::WithThreads(2, [&] { return RenderFog(f.scene, o, {}); });
  EXPECT_EQ(a.slice_xyz, b.slice_xyz);
  EXPECT_EQ(a.slice_shadowed_xyz, b.slice_shadowed_xyz);
  EXPECT_EQ(a.tables[0].xyz, b.tables[0].xyz);
  EXPECT_EQ(a.attenuation, b.attenuation);
}

// The Monte-Carlo reference (path) and `orders` render the same fog: the zenith and a low view,
// segments to 12.5 % and 100 % of the boundary distance (x = (j/2)^3). Measured: -4.4 % to +18.3 %
// (path standard errors 2.2-4.7 %; the +18.3 % is 2.6 of them from a 2 % path estimate's +5.5 %).
// Bound: 6 % + 3 standard errors: the path tracer's 2 sigma interval holds ~92 % of its
// estimates under heavy tails (docs/sky-render.md "Honest error bars"), so 2 would fail one
// element in four of the seeds.
TEST(FogRender, PathAgreesWithOrders) {
  const Fixture& f = Clear();
  FogRenderOptions o = SmallOptions();
  o.lut_width = o.lut_height = 2;
  o.time_mapping = "gt7:2+2";
  o.sun_zenith_deg = {60};
  o.elevations = 2;    // 0 and 90 deg
  o.depths = 2;        // x = 0.125 and 1
  o.azimuth_deg = {90};
  o.attenuation_width = o.attenuation_height = 2;
  FogRender orders = RenderFog(f.scene, o, {});
  o.method = "path";
  Scene coarse = f.scene;
  coarse.tracer.target_relative_error = 0.06;
  FogRender path = RenderFog(coarse, o, {});
  const FogDepthTable& to = orders.tables[0];
  const FogDepthTable& tp = path.tables[0];
  for (size_t i = 0; i < tp.y_stderr.size(); ++i) {
    const double yo = to.xyz[i * 3 + 1], yp = tp.xyz[i * 3 + 1];
    SKYBAKE_LOG("path %.5g +- %.2g, orders %.5g (%+.1f %%)\n", yp, tp.y_stderr[i], yo, 100 * (yo / yp - 1));
    EXPECT_NEAR(yo, yp, 0.06 * yp + 3 * tp.y_stderr[i]) << i;
    EXPECT_GT(tp.y_stderr[i], 0.0f);
  }
}
