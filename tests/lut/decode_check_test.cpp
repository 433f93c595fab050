// The decode check on a physical sky: the clear basis sky
// rendered by a deterministic method on the GT7 mapping at two neighbouring slices, converted
// and packed exactly as lut-pack does (OCIO XYZ -> Linear Rec.2020, R11G11B10F), decoded by the
// reference decoder at the sun angle half-way between the slices (in the time mapping's slice
// coordinate) for every direction of an equirectangular grid, and compared with a direct render
// at that sun angle. Requirement: RMS relative luminance error <= 2 % over the upper hemisphere
// (solid-angle weighted); the figures, the largest error and where it is are printed and listed
// in docs/lut-pack.md.
//
// Method: `single` (deterministic single scattering, quality low) on a 7-wavelength grid, so the
// suite stays fast; the LUT bake uses the pipeline's method (docs/lut-pack.md). The check
// measures the mapping + interpolation + packing, which do not depend on the method.
// Both time mappings are checked: skybake's gt7-quadratic (the default) everywhere, and the talk's
// gt7 everywhere but its first step (0 -> 35.2 deg), whose measured error is printed and is the
// reason for the default (docs/lut-pack.md, "Decisions"). Deep twilight needs multiple scattering:
// those pairs use the `orders` method.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <map>
#include <memory>
#include <numbers>

#include "atmosphere/mie_optics.h"
#include "atmosphere/model_build.h"
#include "color/color.h"
#include "lut/decoder.h"
#include "lut/directions.h"
#include "lut/gt7_mapping.h"
#include "lut/sky_lut.h"
#include "optics/mie_table.h"
#include "optics/particle_type.h"
#include "optics/polydisperse.h"
#include "spectrum/cmf.h"
#include "spectrum/xyz.h"
#include "support/log.h"
#include "transport/sky_method.h"
#include "transport/sky_render.h"

using namespace skybake;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
// Luminance of the moonless natural night sky, ~21.8 mag/arcsec^2 in V at a dark site (Falchi et
// al. 2016, Sci. Adv. 2:e1600377, "natural sky brightness" 22.0 mag/arcsec^2 = 1.7e-4 cd/m^2):
// the floor below which a LUT texel is not compared.
constexpr double kNightSkyCdM2 = 1.7e-4;

struct Scene {
  AtmosphereModel model;
  std::vector<std::array<double, 3>> weights;
  std::unique_ptr<SkyMethod> method;
  AtmosphereSpec spec;
};


// clear.yaml with its OPAC continental aerosol, 400-700 nm in 50 nm steps, CIE 1931 (its XYZ is
// OCIO's reference space: no observer conversion needed here).
const Scene& Clear(const std::string& method = "single") {
  static std::map<std::string, std::unique_ptr<const Scene>> scenes;  // built once per method, freed at exit
  if (scenes.count(method)) return *scenes[method];
  std::unique_ptr<Scene> scene = [&] {
    auto s = std::make_unique<Scene>();
    AtmosphereSpec spec = LoadAtmosphere(SKYBAKE_SOURCE_DIR "/atmospheres/clear.yaml");
    spec.grid = GridSpec{100.0};
    VerticalProfiles prof = ComputeProfiles(spec);
    const WavelengthGrid grid = WavelengthGrid::Uniform(400, 700, 50);
    mie::ParticleType type = mie::LoadParticleType(*spec.aerosols[0].particle);
    mie::MieBuildOptions mo;
    mo.fits = false;
    auto table = std::make_shared<mie::MieTable>(mie::BuildMieTable(type, grid.wavelength_nm(), mo).table);
    std::vector<AerosolOptics> aerosols = {AerosolOpticsFromMie(spec.aerosols[0].name, table, grid)};
    s->model = BuildAtmosphereModel(spec, prof, grid, aerosols, ModelOptions{}, nullptr);
    XyzWeights w(grid, Cmf::LoadDefault(Observer::kCie1931_2deg));
    for (size_t i = 0; i < grid.size(); ++i) s->weights.push_back({w.wx()[i], w.wy()[i], w.wz()[i]});
    SkyMethodOptions o;
    o.quality = Quality::kLow;
    s->method = MakeSkyMethod(method, s->model, o, nullptr);
    s->spec = spec;
    return s;
  }();
  scenes[method] = std::move(scene);
  return *scenes[method];
}

SkyRenderResult Render(const Scene& sc, std::shared_ptr<const SkyMapping> mapping, std::vector<double> zenith_deg) {
  SkyRenderSettings st;
  st.mapping = std::move(mapping);
  st.sun_zenith_deg = std::move(zenith_deg);
  st.ambient = false;
  st.transmittance_angles = 2;
  return RenderSkyDeterministic(*sc.method, sc.model, sc.weights, st, nullptr);
}

// The sun zenith angle at slice coordinate s (bisection on the monotonic inverse).
double ZenithAt(const gt7::TimeMapping& t, double s) {
  double lo = 0.0, hi = 100.0 * kDeg;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (t.SliceCoordinate(mid) < s ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

struct Figures {
  double rms = 0.0, rms_outside_5deg = 0.0, max = 0.0;
  double max_zenith = 0.0, max_azimuth = 0.0, max_sun_angle = 0.0;
};

// Packs slices i and i+1 at 32 x 128, decodes at the mid angle, compares with a direct
// equirectangular 64 x 32 render (upper hemisphere).
Figures CheckPair(const std::string& time_mapping, int i, const std::string& method = "single",
                  lut::TimeInterpolation interp = lut::TimeInterpolation::kGeometric) {
  const Scene& sc = Clear(method);
  const gt7::TimeMapping time = gt7::TimeMapping::FromName(time_mapping, sc.spec.planet->radius_m, sc.spec.planet->top_m,
                                                           sc.spec.observer_altitude_m);
  const int w = 32, h = 128;
  const double t0 = time.SliceZenithRad(i), t1 = time.SliceZenithRad(i + 1);
  const SkyRenderResult lut = Render(sc, std::make_shared<gt7::Gt7SkyMapping>(w, h), {t0 / kDeg, t1 / kDeg});
  const ColorConfig config = ColorConfig::Load();
  const ColorProcessor to2020 = config.Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  // All 64 slices, zero except the two the decoder reads at this angle.
  const size_t per = static_cast<size_t>(w) * h * 3;
  std::vector<float> rgb(per * time.slices(), 0.0f);
  for (int k = 0; k < 2; ++k) {
    std::vector<float> s = lut.slices[k].xyz;
    to2020.Apply(s);
    std::copy(s.begin(), s.end(), rgb.begin() + static_cast<std::ptrdiff_t>(per * (i + k)));
  }
  const lut::PackedTexture packed = lut::PackRgb(w, h, time.slices(), rgb, 1.0, to_xyz);
  lut::SkyLutDecoder dec(w, h, time, gt7::SphereMapping{}, packed.decoded_rgb, {0, 0, 0});
  dec.set_time_interpolation(interp);

  const double tm = ZenithAt(time, i + 0.5);
  const DirectionGrid grid{DirectionMapping::kEquirectangular, 64, 32};
  const SkyRenderResult direct = Render(sc, MakeStaticMapping(grid), {tm / kDeg});
  std::vector<float> decoded;
  std::vector<std::array<double, 3>> dirs;
  for (int y = 0; y < grid.height / 2; ++y) {  // upper hemisphere: rows above the horizon
    for (int x = 0; x < grid.width; ++x) {
      dirs.push_back(*grid.TexelDirection(x, y));
      const std::array<double, 3> l = dec.Radiance(dirs.back(), tm);
      for (double c : l) decoded.push_back(static_cast<float>(c));
    }
  }
  to_xyz.Apply(decoded);
  Figures f;
  double w_all = 0, e2_all = 0, w_out = 0, e2_out = 0;
  for (size_t t = 0; t < dirs.size(); ++t) {
    const int x = static_cast<int>(t % grid.width), y = static_cast<int>(t / grid.width);
    const double y_direct = direct.slices[0].xyz[t * 3 + 1];
    // Texels darker than the natural night sky are not compared (relative errors of nothing):
    // single scattering leaves the Earth's shadow nearly black in deep twilight.
    if (!(y_direct > kNightSkyCdM2)) continue;
    const double e = (decoded[t * 3 + 1] - y_direct) / y_direct;
    const double sa = grid.TexelSolidAngle(x, y);
    const std::array<double, 3>& d = dirs[t];
    const double sun_angle = std::acos(std::clamp(d[0] * std::sin(tm) + d[2] * std::cos(tm), -1.0, 1.0)) / kDeg;
    w_all += sa;
    e2_all += sa * e * e;
    if (sun_angle > 5.0) {
      w_out += sa;
      e2_out += sa * e * e;
    }
    if (std::fabs(e) > std::fabs(f.max)) {
      f.max = e;
      f.max_zenith = std::acos(d[2]) / kDeg;
      f.max_azimuth = std::atan2(d[1], d[0]) / kDeg;
      f.max_sun_angle = sun_angle;
    }
  }
  f.rms = std::sqrt(e2_all / w_all);
  f.rms_outside_5deg = std::sqrt(e2_out / w_out);
  SKYBAKE_LOG("%s %s %s slices %2d-%2d, sun zenith %7.3f deg (%s/%s): RMS %.3f %% (%.3f %% outside 5 deg of the sun), max %+.2f %% at "
              "zenith %.1f, azimuth %.1f, %.1f deg from the sun\n",
              method.c_str(), lut::TimeInterpolationName(interp), time_mapping.c_str(), i, i + 1, tm / kDeg, gt7::SphereFamilyName(gt7::SphereMapping{}.FamilyFor(t0)),
              gt7::SphereFamilyName(gt7::SphereMapping{}.FamilyFor(t1)), 100 * f.rms, 100 * f.rms_outside_5deg, 100 * f.max,
              f.max_zenith, f.max_azimuth, f.max_sun_angle);
  return f;
}

}  // namespace

TEST(DecodeCheck, QuadraticTimeMappingWithinTwoPercentRms) {
  // Pairs from the zenith sun to 1 deg below the horizon: high sun, mid sun, the pair straddling
  // the threshold (23-24: two families), low sun, the 90 deg pair, early twilight. Deeper
  // twilight needs multiple scattering (below).
  for (int i : {0, 1, 5, 10, 16, 23, 30, 40, 46, 48, 52}) {
    const Figures f = CheckPair("gt7-quadratic", i);
    EXPECT_LE(f.rms, 0.02) << "slices " << i << "-" << i + 1;
  }
}

TEST(DecodeCheck, DeepTwilightWithMultipleScattering) {
  // Below -1 deg the single-scattering sky is black in the Earth's shadow and its terminator
  // sweeps across the sky: a method with multiple scattering is needed for a meaningful check.
  // The geometric time interpolation stays within 2.5 % (measured 0.8-2.3 % with `orders`;
  // 2.3 % at slices 60-61, sun 96.9 deg, where `orders` itself interpolates its
  // tables linearly between sun nodes 1 deg apart while the twilight sky falls ~e-fold per
  // degree: docs/sky-methods.md "Twilight"); the linear one is 15-21 % off half-way in deep
  // twilight and is printed for the record.
  for (int i : {54, 56, 58, 60, 62}) {
    const Figures f = CheckPair("gt7-quadratic", i, "orders");
    EXPECT_LE(f.rms, 0.025) << "slices " << i << "-" << i + 1;
    CheckPair("gt7-quadratic", i, "orders", lut::TimeInterpolation::kLinear);
  }
}

TEST(DecodeCheck, TalksTimeMappingWithinTwoPercentRmsExceptItsFirstStep) {
  for (int i : {1, 5, 10, 11, 20, 30, 40, 46, 48, 52}) {  // 11-12 straddles the threshold
    const Figures f = CheckPair("gt7", i);
    EXPECT_LE(f.rms, 0.02) << "slices " << i << "-" << i + 1;
  }
  // The first step, sun zenith 0 -> 35.2 deg, is too wide to interpolate in either frame: 3.6 %
  // RMS half-way with the default blend (14 % with the talk's linear blend in the slice
  // coordinate). Should this ever pass, revisit the gt7-quadratic default.
  EXPECT_GT(CheckPair("gt7", 0).rms, 0.02);
}
