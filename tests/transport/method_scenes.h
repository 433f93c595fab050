// Scenes shared by the sky-method tests (method_*_test.cpp, stability_test.cpp): the repository's
// clear and hazed atmospheres on a coarse wavelength grid (so the Mie tables are built in the
// test in a few seconds), and a homogeneous shell with closed forms.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "atmosphere/mie_optics.h"
#include "atmosphere/model_build.h"
#include "io/csv.h"
#include "io/error.h"
#include "io/fileio.h"
#include "optics/particle_type.h"
#include "optics/polydisperse.h"
#include "spectrum/cmf.h"
#include "spectrum/xyz.h"
#include "transport/path_tracer.h"
#include "transport/sky_method.h"

namespace skybake::testing {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDeg = kPi / 180.0;

struct TestScene {
  AtmosphereModel model;
  std::vector<std::array<double, 3>> weights;  // CIE 1931 XYZ weights on the grid
  // Y (cd/m^2) of a spectral radiance on the grid.
  double Y(const double* L) const {
    double y = 0.0;
    for (size_t w = 0; w < weights.size(); ++w) y += weights[w][1] * L[w];
    return y;
  }
};

struct SceneOptions {
  double aerosol_tau_550 = -1.0;  // < 0: the file's
  AerosolPhase phase = AerosolPhase::kTabulated;
  bool aerosols = true;
  double step_nm = 20.0;  // wavelength grid step from 380 to 780 nm
};

// atmospheres/<name>.yaml with its particle type, 100 m levels, 380-780 nm at 20 nm (21 samples).
inline TestScene LoadTestScene(const std::string& name, const SceneOptions& o = {}) {
  AtmosphereSpec spec = LoadAtmosphere(SKYBAKE_SOURCE_DIR "/atmospheres/" + name + ".yaml");
  spec.grid = GridSpec{100.0};
  if (o.aerosol_tau_550 >= 0.0) {
    for (AerosolLayerSpec& a : spec.aerosols) a.scale->value = o.aerosol_tau_550;
  }
  VerticalProfiles prof = ComputeProfiles(spec);
  const WavelengthGrid grid = WavelengthGrid::Uniform(380, 780, o.step_nm);
  std::vector<AerosolOptics> aerosols;
  if (o.aerosols) {
    for (const AerosolLayerSpec& layer : spec.aerosols) {
      mie::ParticleType type = mie::LoadParticleType(*layer.particle);
      mie::MieBuildOptions mo;
      mo.fits = o.phase != AerosolPhase::kTabulated;
      auto table = std::make_shared<mie::MieTable>(mie::BuildMieTable(type, grid.wavelength_nm(), mo).table);
      aerosols.push_back(AerosolOpticsFromMie(layer.name, table, grid, o.phase));
    }
  }
  ModelOptions mopt;
  mopt.aerosols = o.aerosols;
  TestScene s;
  s.model = BuildAtmosphereModel(spec, prof, grid, aerosols, mopt, nullptr);
  XyzWeights w(grid, Cmf::LoadDefault(Observer::kCie1931_2deg));
  for (size_t i = 0; i < grid.size(); ++i) s.weights.push_back({w.wx()[i], w.wy()[i], w.wz()[i]});
  return s;
}

// A homogeneous shell R < r < R + H with per-wavelength scattering and absorption (m^-1), one
// phase model, a constant ground albedo and a point-like sun of irradiance 1.
inline AtmosphereModel Homogeneous(double R, double H, std::vector<double> sigma_s, std::vector<double> sigma_a,
                                   std::shared_ptr<const PhaseModel> phase, double albedo, size_t levels = 2) {
  AtmosphereModel m;
  m.bottom_radius_m = R;
  m.top_radius_m = R + H;
  const size_t nw = sigma_s.size();
  for (size_t i = 0; i < levels; ++i) m.altitude_m.push_back(H * static_cast<double>(i) / static_cast<double>(levels - 1));
  for (size_t w = 0; w < nw; ++w) m.wavelength_nm.push_back(400.0 + 100.0 * static_cast<double>(w));
  MediumComponent c;
  c.name = "test";
  c.phase = std::move(phase);
  for (size_t i = 0; i < levels; ++i) {
    for (size_t w = 0; w < nw; ++w) {
      c.scattering.push_back(sigma_s[w]);
      c.absorption.push_back(sigma_a[w]);
    }
  }
  m.components.push_back(c);
  m.ground_albedo.assign(nw, albedo);
  m.sun.irradiance.assign(nw, 1.0);
  m.sun.angular_radius_rad = 1e-4;
  m.Finalize();
  return m;
}

// The local-frame direction of view zenith theta and azimuth phi from the sun (deg).
inline std::array<double, 3> Dir(double theta_deg, double phi_deg) {
  const double t = theta_deg * kDeg, p = phi_deg * kDeg;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// The sky-method tests' directions away from the aureole (view zenith, azimuth from the sun, deg):
// zenith, mid sky, low sky and the horizon band, towards, across and away from the sun, and one
// below the horizon.
inline const std::vector<std::array<double, 2>>& SkyAngles() {
  static const std::vector<std::array<double, 2>> a = {{0, 0},   {40, 90}, {60, 180}, {75, 45},   {85, 120},
                                                       {88, 10}, {88, 90}, {88, 180}, {89.5, 60}, {95, 150}};
  return a;
}
inline const std::vector<std::array<double, 3>>& SkyDirs() {
  static const std::vector<std::array<double, 3>> d = [] {
    std::vector<std::array<double, 3>> v;
    for (const auto& a : SkyAngles()) v.push_back(Dir(a[0], a[1]));
    return v;
  }();
  return d;
}

// A few numbers that change when the scene does (per component: the column scattering and
// absorption optical depths at the grid's first, middle and last wavelength and the phase
// function at 0, 90 and 180 deg at the middle one; the ground albedo and the sun's irradiance at
// the middle one), so that a cached path reference of the scene can tell that it is stale.
inline std::vector<double> SceneFingerprint(const TestScene& sc) {
  const AtmosphereModel& m = sc.model;
  const size_t nw = m.wavelengths(), mid = nw / 2;
  std::vector<double> f;
  for (const MediumComponent& c : m.components) {
    for (size_t w : {size_t{0}, mid, nw - 1}) {
      double ts = 0.0, ta = 0.0;
      for (size_t l = 0; l + 1 < m.levels(); ++l) {
        const double dz = m.altitude_m[l + 1] - m.altitude_m[l];
        ts += 0.5 * (c.scattering[l * nw + w] + c.scattering[(l + 1) * nw + w]) * dz;
        ta += 0.5 * (c.absorption[l * nw + w] + c.absorption[(l + 1) * nw + w]) * dz;
      }
      f.push_back(ts);
      f.push_back(ta);
    }
    for (double mu : {1.0, 0.0, -1.0}) f.push_back(c.phase ? c.phase->Eval(mid, mu) : 0.0);
  }
  f.push_back(m.ground_albedo[mid]);
  f.push_back(m.sun.irradiance[mid]);
  return f;
}

// Y (cd/m^2) of a method's sky seen from 1 m above the ground, per direction.
inline std::vector<double> MethodY(const TestScene& sc, const SkyMethod& method, double sun_zenith_deg,
                                   const std::vector<std::array<double, 3>>& dirs) {
  std::vector<double> L;
  method.Radiance(1.0, sun_zenith_deg * kDeg, dirs, &L);
  std::vector<double> y;
  for (size_t d = 0; d < dirs.size(); ++d) y.push_back(sc.Y(L.data() + d * sc.model.wavelengths()));
  return y;
}

// A cached path reference of the tests' scene (tests/transport/references/, made by
// bench_test_references): Y and its standard error per SkyDirs direction, and whether its
// fingerprint is the scene's (each number within 1e-6 relative); `source` is its command line.
struct CachedReference {
  std::vector<double> y, y_stderr;
  bool same_scene = false;
  std::string path, source;
};

inline std::string CachedReferencePath(const std::string& name) {
  return std::string(SKYBAKE_SOURCE_DIR) + "/tests/transport/references/" + name;
}

inline CachedReference ReadCachedReference(const std::string& name, const TestScene& sc) {
  CachedReference r;
  r.path = CachedReferencePath(name);
  const std::string text = ReadFileBytes(r.path);
  const CsvTable csv = CsvTable::Parse(text, r.path);
  r.source = csv.source();
  std::vector<double> stored;
  const size_t at = text.find("\n# scene:");
  if (at != std::string::npos) {
    std::istringstream ss(text.substr(at + 9, text.find('\n', at + 1) - at - 9));
    for (double v; ss >> v;) stored.push_back(v);
  }
  const std::vector<double> now = SceneFingerprint(sc);
  r.same_scene = stored.size() == now.size();
  for (size_t i = 0; r.same_scene && i < now.size(); ++i) {
    r.same_scene = std::abs(stored[i] - now[i]) <= 1e-6 * std::max(std::abs(now[i]), 1e-30);
  }
  if (!r.same_scene) return r;
  Diagnostics d;
  r.y = csv.Numbers("Y_cd_m2", d);
  r.y_stderr = csv.Numbers("Y_stderr_cd_m2", d);
  d.ThrowIfAny();
  return r;
}

}  // namespace skybake::testing
