#include "fog/fog_luts.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <optional>
#include <tuple>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "color/exr_color.h"
#include "io/error.h"
#include "io/png_label.h"
#include "io/yaml.h"
#include "lut/dds.h"
#include "lut/inspection.h"
#include "lut/ktx2.h"
#include "skybake/version.h"
#include "spectrum/cmf.h"
#include "spectrum/grid.h"
#include "spectrum/xyz.h"

namespace fs = std::filesystem;

namespace skybake::fog {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::array<double, 3> DirOf(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * kDeg, a = azimuth_deg * kDeg;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

// Accumulates ErrorStats serially.
struct Accumulator {
  ErrorStats s;
  double sum2 = 0.0;
  std::array<double, 3> c2{0, 0, 0};
  std::array<size_t, 3> cn{0, 0, 0};
  void Add(double e, const std::array<double, 3>& ec, double sza, double elev, double az, double depth_m, double x) {
    ++s.count;
    sum2 += e * e;
    if (std::fabs(e) > s.max) {
      s.max = std::fabs(e);
      s.max_sun_zenith_deg = sza;
      s.max_elevation_deg = elev;
      s.max_azimuth_deg = az;
      s.max_depth_m = depth_m;
      s.max_x = x;
    }
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(ec[c])) {
        c2[c] += ec[c] * ec[c];
        ++cn[c];
      }
    }
  }
  ErrorStats Done() const {
    ErrorStats o = s;
    o.rms = s.count ? std::sqrt(sum2 / static_cast<double>(s.count)) : 0.0;
    for (int c = 0; c < 3; ++c) o.channel_rms[c] = cn[c] ? std::sqrt(c2[c] / static_cast<double>(cn[c])) : 0.0;
    return o;
  }
};

struct ProductAccumulator {
  Accumulator all, near, horizon, near_horizon, far, infinite_depth;
  std::vector<Accumulator> near_per_sun, all_per_sun;
  ProductStats Done() const {
    ProductStats p{all.Done(), near.Done(), horizon.Done(), near_horizon.Done(), far.Done(), infinite_depth.Done(), {}, {}};
    for (const Accumulator& a : near_per_sun) p.near_per_sun.push_back(a.Done());
    for (const Accumulator& a : all_per_sun) p.all_per_sun.push_back(a.Done());
    return p;
  }
};

// Linear Rec.2020 -> Y (the OCIO transform is linear between these linear spaces).
std::array<double, 3> LuminanceRow(const ColorProcessor& to_xyz) {
  std::array<double, 3> row{};
  for (int c = 0; c < 3; ++c) {
    std::array<float, 3> e{0, 0, 0};
    e[c] = 1.0f;
    row[c] = to_xyz.Apply(e)[1];
  }
  return row;
}

double Dot(const std::array<double, 3>& a, const std::array<double, 3>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

const char* ParamModeName(ParamMode m) {
  switch (m) {
    case ParamMode::kGlobal:
      return "global";
    case ParamMode::kPerSlice:
      return "per-slice";
    case ParamMode::kPerSliceElevation:
      return "per-slice-elevation";
  }
  return "?";
}

std::optional<ParamMode> ParseParamMode(const std::string& name) {
  for (ParamMode m : {ParamMode::kGlobal, ParamMode::kPerSlice, ParamMode::kPerSliceElevation}) {
    if (name == ParamModeName(m)) return m;
  }
  return std::nullopt;
}

FogEvaluator MakeEvaluator(const FogProducts& p) {
  const lut::SkyRender& r = p.layout;
  lut::SkyLutDecoder fog(r.width, r.height, r.time, r.sphere, p.fog.decoded_rgb, {0, 0, 0}, p.options.night_end_zenith_deg);
  lut::SkyLutDecoder sh(r.width, r.height, r.time, r.sphere, p.shadowed.decoded_rgb, {0, 0, 0}, p.options.night_end_zenith_deg);
  fog.set_texel_grid(p.texel_grid);
  sh.set_texel_grid(p.texel_grid);
  AttenuationLut att(p.attenuation.width, p.attenuation.height, p.attenuation.decoded_rgb);
  return FogEvaluator(p.params, std::move(fog), std::move(sh), std::move(att));
}

FogProducts BuildFogProducts(const FogRender& render, const std::string& sky, const FogFitOptions& o,
                             const ColorConfig& config, std::vector<fs::path>* files_read) {
  FogProducts out;
  out.sky = sky;
  out.options = o;
  const FogGeometry geo = render.geometry();
  const ColorProcessor to2020 = config.Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  const std::array<double, 3> y_row = LuminanceRow(to_xyz);

  const size_t ne = render.elevation_deg.size(), na = render.azimuth_deg.size(), nx = render.depth_x.size();
  const size_t n_tab = render.tables.size();
  // Reference fog in Linear Rec.2020, per table.
  std::vector<std::vector<float>> ref(n_tab), ref_sh(n_tab);
  for (size_t s = 0; s < n_tab; ++s) {
    ref[s] = render.tables[s].xyz;
    ref_sh[s] = render.tables[s].shadowed_xyz;
    to2020.Apply(ref[s]);
    to2020.Apply(ref_sh[s]);
  }
  std::vector<double> mu(ne), theta(ne), depth_max(ne);
  for (size_t e = 0; e < ne; ++e) {
    mu[e] = std::sin(render.elevation_deg[e] * kDeg);
    theta[e] = geo.Theta(o.angle, mu[e]);
    depth_max[e] = geo.BoundaryDistanceM(mu[e]);
  }

  // ---- Fits. Samples: every (selected) table, elevation, azimuth and depth x < 1 of the reference,
  // the target the fog at x over the fog at x = 1 of the same direction and sun.
  const size_t n_fit_tables = [&] {
    out.table_in_fit.assign(n_tab, o.fit_sun_zenith_deg.empty());
    for (double z : o.fit_sun_zenith_deg) {
      bool found = false;
      for (size_t s = 0; s < n_tab; ++s) {
        if (std::fabs(render.tables[s].sun_zenith_deg - z) <= 1e-9) {
          out.table_in_fit[s] = true;
          found = true;
        }
      }
      if (!found) {
        std::string have;
        for (const FogDepthTable& t : render.tables) have += (have.empty() ? "" : ", ") + FormatExact(t.sun_zenith_deg);
        throw UsageError(fmt::format("--fit-sun-zenith-deg: {} deg is not a depth table of {} ({} deg)", FormatExact(z),
                                     render.path, have));
      }
    }
    return static_cast<size_t>(std::count(out.table_in_fit.begin(), out.table_in_fit.end(), true));
  }();
  SKYBAKE_CHECK(n_fit_tables > 0);
  // Fits (a, p) per channel (or once on luminance, copied to R, G, B) on the samples of the
  // (table, azimuth, elevation) triples `use` selects (one elevation: p = 0, k = a).
  auto fit_on = [&](const std::vector<std::vector<float>>& data, const std::function<bool(size_t, size_t, size_t)>& use) {
    std::array<FitResult, 3> fits;
    const int channels = o.per_channel ? 3 : 1;
    for (int c = 0; c < channels; ++c) {
      std::vector<FitSample> samples;
      samples.reserve(n_tab * ne * na * nx);
      for (size_t s = 0; s < n_tab; ++s) {
        for (size_t e = 0; e < ne; ++e) {
          for (size_t az = 0; az < na; ++az) {
            if (!use(s, az, e)) continue;
            const size_t i1 = render.TableIndex(e, az, nx - 1);
            const double v1 = o.per_channel ? data[s][i1 * 3 + c] : Dot(y_row, {data[s][i1 * 3], data[s][i1 * 3 + 1], data[s][i1 * 3 + 2]});
            for (size_t j = 0; j + 1 < nx; ++j) {
              const size_t i = render.TableIndex(e, az, j);
              const double v = o.per_channel ? data[s][i * 3 + c] : Dot(y_row, {data[s][i * 3], data[s][i * 3 + 1], data[s][i * 3 + 2]});
              samples.push_back({theta[e], render.depth_x[j], v1 > 0.0 ? v / v1 : -1.0});
            }
          }
        }
      }
      const FitResult f = FitDepthFactor(samples, o.fit);
      for (int k = (o.per_channel ? c : 0); k < (o.per_channel ? c + 1 : 3); ++k) fits[static_cast<size_t>(k)] = f;
    }
    return fits;
  };
  auto as_params = [](const std::array<FitResult, 3>& f, std::array<double, 3>* a, std::array<double, 3>* p) {
    for (size_t c = 0; c < 3; ++c) {
      (*a)[c] = f[c].a;
      (*p)[c] = f[c].p;
    }
  };
  FogParams& par = out.params;
  par.basis_sky = sky;
  par.angle = o.angle;
  par.planet_radius_m = render.planet_radius_m;
  par.observer_altitude_m = render.observer_altitude_m;
  par.cut_altitude_m = render.cut_altitude_m;
  // Elevations the fits use: every fit_elevation_stride-th row of the tables, and the last.
  SKYBAKE_CHECK(o.fit_elevation_stride >= 1);
  out.elevation_in_fit.assign(ne, false);
  for (size_t e = 0; e < ne; e += static_cast<size_t>(o.fit_elevation_stride)) out.elevation_in_fit[e] = true;
  out.elevation_in_fit[ne - 1] = true;
  auto in_fit = [&](size_t s, size_t e) { return out.table_in_fit[s] && out.elevation_in_fit[e]; };
  out.fit_fog = fit_on(ref, [&](size_t s, size_t, size_t e) { return in_fit(s, e); });
  out.fit_shadowed = fit_on(ref_sh, [&](size_t s, size_t, size_t e) { return in_fit(s, e); });
  as_params(out.fit_fog, &par.a, &par.p);
  as_params(out.fit_shadowed, &par.a_shadowed, &par.p_shadowed);
  // Per depth table (the diagnostics use every table; the per-slice parameters the selected ones).
  out.table_fit_fog.resize(n_tab);
  out.table_fit_shadowed.resize(n_tab);
  for (size_t s = 0; s < n_tab; ++s) {
    out.table_fit_fog[s] = fit_on(ref, [&](size_t s2, size_t, size_t e) { return s2 == s && out.elevation_in_fit[e]; });
    out.table_fit_shadowed[s] = fit_on(ref_sh, [&](size_t s2, size_t, size_t e) { return s2 == s && out.elevation_in_fit[e]; });
  }
  if (o.params != ParamMode::kGlobal) {
    // Per slice: ln a and p piecewise linear in the sun zenith angle between the selected tables
    // whose fit had samples (sorted by angle), constant beyond the first and the last.
    // `weights(fits, sza)`: (table lo, table hi, weight of hi), or nullopt without usable tables.
    auto weights = [&](const std::vector<std::array<FitResult, 3>>& fits, double sza) -> std::optional<std::tuple<size_t, size_t, double>> {
      std::vector<std::pair<double, size_t>> nodes;
      for (size_t s = 0; s < n_tab; ++s) {
        if (out.table_in_fit[s] && fits[s][0].used > 0 && fits[s][1].used > 0 && fits[s][2].used > 0) {
          nodes.push_back({render.tables[s].sun_zenith_deg, s});
        }
      }
      std::sort(nodes.begin(), nodes.end());
      if (nodes.empty()) return std::nullopt;
      size_t hi = 0;
      while (hi < nodes.size() && nodes[hi].first < sza) ++hi;
      const size_t lo = hi == 0 ? 0 : hi - 1;
      hi = std::min(hi, nodes.size() - 1);
      const double w = nodes[hi].first > nodes[lo].first ? std::clamp((sza - nodes[lo].first) / (nodes[hi].first - nodes[lo].first), 0.0, 1.0) : 0.0;
      return std::tuple<size_t, size_t, double>{nodes[lo].second, nodes[hi].second, w};
    };
    // Per slice and elevation: for each selected table s and fit elevation e, k fitted on that
    // elevation alone (all azimuths; one theta, so the fit's a is k), stored as a_se = k / theta_e^p_s
    // with the table's own p: a_se = a_s reproduces the per-slice model, and theta^p keeps the
    // fast variation of k near the horizon out of the interpolation in v.
    std::vector<size_t> nodes_e;
    for (size_t e = 0; e < ne; ++e) {
      if (out.elevation_in_fit[e]) nodes_e.push_back(e);
    }
    std::vector<std::vector<std::array<double, 3>>> a_se(n_tab), a_se_sh(n_tab);
    if (o.params == ParamMode::kPerSliceElevation) {
      for (size_t e : nodes_e) par.node_v.push_back(AttenuationV(mu[e]));
      for (size_t s = 0; s < n_tab; ++s) {
        if (!out.table_in_fit[s]) continue;
        for (int prod = 0; prod < 2; ++prod) {
          const std::array<FitResult, 3>& table = prod ? out.table_fit_shadowed[s] : out.table_fit_fog[s];
          auto& dst = prod ? a_se_sh[s] : a_se[s];
          for (size_t e : nodes_e) {
            const std::array<FitResult, 3> k = fit_on(prod ? ref_sh : ref, [&](size_t s2, size_t, size_t e2) { return s2 == s && e2 == e; });
            std::array<double, 3> v{};
            for (size_t c = 0; c < 3; ++c) {
              // No usable sample at this elevation: the table's own a.
              v[c] = k[c].used > 0 ? k[c].a / DepthExponent(1.0, table[c].p, theta[e]) : table[c].a;
            }
            dst.push_back(v);
          }
        }
      }
    }
    for (double sza : render.slice_zenith_deg) {
      FogParams::Slice q;
      for (int prod = 0; prod < 2; ++prod) {
        const std::vector<std::array<FitResult, 3>>& fits = prod ? out.table_fit_shadowed : out.table_fit_fog;
        const std::array<FitResult, 3>& global = prod ? out.fit_shadowed : out.fit_fog;
        std::array<double, 3>& a = prod ? q.a_shadowed : q.a;
        std::array<double, 3>& p = prod ? q.p_shadowed : q.p;
        std::vector<std::array<double, 3>>& an = prod ? q.a_shadowed_nodes : q.a_nodes;
        const auto wt = weights(fits, sza);
        if (!wt) {
          as_params(global, &a, &p);
          if (o.params == ParamMode::kPerSliceElevation) an.assign(nodes_e.size(), a);
          continue;
        }
        const auto [lo, hi, w] = *wt;
        for (size_t c = 0; c < 3; ++c) {
          a[c] = std::exp((1 - w) * std::log(fits[lo][c].a) + w * std::log(fits[hi][c].a));
          p[c] = (1 - w) * fits[lo][c].p + w * fits[hi][c].p;
        }
        if (o.params == ParamMode::kPerSliceElevation) {
          const auto& A = prod ? a_se_sh : a_se;
          for (size_t j = 0; j < nodes_e.size(); ++j) {
            std::array<double, 3> v{};
            for (size_t c = 0; c < 3; ++c) v[c] = std::exp((1 - w) * std::log(A[lo][j][c]) + w * std::log(A[hi][j][c]));
            an.push_back(v);
          }
        }
      }
      par.slices.push_back(q);
    }
  }

  // ---- Pack the LUTs.
  lut::SkyRender& lay = out.layout;
  lay.path = render.path;
  lay.width = render.lut_width;
  lay.height = render.lut_height;
  lay.time = render.time;
  lay.time_mapping_name = render.time_mapping_name;
  lay.sphere = render.sphere;
  lay.slice_zenith_deg = render.slice_zenith_deg;
  lay.observer = render.observer;
  lay.method = render.method;
  out.texel_grid = render.texel_grid;
  const int n_slices = static_cast<int>(render.slice_zenith_deg.size());
  auto pack_slices = [&](const std::vector<std::vector<float>>& slices) {
    std::vector<float> rgb;
    for (const std::vector<float>& s : slices) rgb.insert(rgb.end(), s.begin(), s.end());
    to2020.Apply(rgb);
    return lut::PackRgb(render.lut_width, render.lut_height, n_slices, rgb, lut::AutomaticScale(rgb), to_xyz);
  };
  out.fog = pack_slices(render.slice_xyz);
  out.shadowed = pack_slices(render.slice_shadowed_xyz);

  // Attenuation: sunlight-weighted channel transmittance, [E0 T]_c / [E0]_c (as lut-pack's
  // transmittance LUT; lut/sky_lut.cpp BuildLutSet), Linear Rec.2020.
  const std::optional<Observer> obs = ParseObserver(render.observer);
  if (!obs) throw InputError(FileLoc{render.path, 0}, "unknown observer '" + render.observer + "'");
  const Cmf cmf = Cmf::LoadDefault(*obs);
  if (files_read) files_read->push_back(cmf.path());
  const XyzWeights w(WavelengthGrid::List(render.wavelength_nm, FileLoc{render.path, 0}), cmf);
  const ColorProcessor obs_to2020 = config.Converter(XyzColorSpace(*obs), ocio_names::kLinearRec2020);
  const size_t nw = render.wavelength_nm.size();
  auto sun_rgb = [&](const float* T) {
    std::vector<double> spec(nw);
    for (size_t l = 0; l < nw; ++l) spec[l] = render.sun_e0[l] * (T ? T[l] : 1.0);
    const Xyz x = w.Integrate(std::span<const double>(spec));
    return obs_to2020.Apply(std::array<float, 3>{static_cast<float>(x.X), static_cast<float>(x.Y), static_cast<float>(x.Z)});
  };
  const std::array<float, 3> e0_rgb = sun_rgb(nullptr);
  for (int c = 0; c < 3; ++c) {
    if (!(e0_rgb[c] > 0.0f)) throw InputError(FileLoc{render.path, 0}, "the sun's colour has a non-positive Rec.2020 channel");
  }
  auto t_rgb = [&](const float* T) {
    const std::array<float, 3> c = sun_rgb(T);
    return std::array<float, 3>{c[0] / e0_rgb[0], c[1] / e0_rgb[1], c[2] / e0_rgb[2]};
  };
  {
    std::vector<float> rgb;
    const size_t nodes = static_cast<size_t>(render.attenuation_width) * render.attenuation_height;
    for (size_t q = 0; q < nodes; ++q) {
      const std::array<float, 3> c = t_rgb(&render.attenuation[q * nw]);
      rgb.insert(rgb.end(), c.begin(), c.end());
    }
    out.attenuation = lut::PackRgb(render.attenuation_width, render.attenuation_height, 1, rgb, lut::AutomaticScale(rgb), to_xyz);
  }

  // ---- Errors. Fit: ref(x = 1) F(x); evaluator: the packed textures.
  const FogEvaluator eval = MakeEvaluator(out);
  ProductAccumulator acc[4];  // fog fit, fog eval, shadowed fit, shadowed eval
  for (ProductAccumulator& a : acc) {
    a.near_per_sun.resize(n_tab);
    a.all_per_sun.resize(n_tab);
  }
  out.residual_fog_fit.assign(n_tab, std::vector<float>(ne * na * nx, kNaN));
  out.residual_fog_eval = out.residual_shadowed_fit = out.residual_shadowed_eval = out.residual_fog_fit;
  out.residual_fog_eval_rgb.assign(n_tab, std::vector<std::array<float, 3>>(ne * na * nx, {kNaN, kNaN, kNaN}));
  double noise2 = 0.0;
  size_t noise_n = 0;
  for (size_t s = 0; s < n_tab; ++s) {
    const double sza = render.tables[s].sun_zenith_deg;
    for (size_t e = 0; e < ne; ++e) {
      const FogParams::Slice q = eval.ParamsAt(sza * kDeg, mu[e]);  // what the evaluator uses at this sun angle and elevation
      for (size_t az = 0; az < na; ++az) {
        const std::array<double, 3> dir = DirOf(render.elevation_deg[e], render.azimuth_deg[az]);
        const size_t i1 = render.TableIndex(e, az, nx - 1);
        for (size_t j = 0; j < nx; ++j) {
          const size_t i = render.TableIndex(e, az, j);
          const double x = render.depth_x[j];
          const double depth_m = x * depth_max[e];
          const FogValue v = eval.Evaluate(dir, j + 1 == nx ? depth_max[e] * 2.0 : depth_m, sza * kDeg, 0.0);
          const FogValue vs = eval.Evaluate(dir, j + 1 == nx ? depth_max[e] * 2.0 : depth_m, sza * kDeg, 1.0);
          for (int prod = 0; prod < 2; ++prod) {
            const std::vector<float>& d = prod ? ref_sh[s] : ref[s];
            const std::array<double, 3> rc{d[i * 3], d[i * 3 + 1], d[i * 3 + 2]};
            const std::array<double, 3> r1{d[i1 * 3], d[i1 * 3 + 1], d[i1 * 3 + 2]};
            const double y_ref = Dot(y_row, rc);
            if (!(y_ref > 0.0)) {
              if (prod == 0) ++out.excluded_samples;
              continue;
            }
            if (prod == 0 && render.tables[s].y_stderr[i] > 0.0f) {
              const double rel = render.tables[s].y_stderr[i] / render.tables[s].xyz[i * 3 + 1];
              noise2 += rel * rel;
              ++noise_n;
            }
            std::array<double, 3> fit{}, ev = prod ? vs.inscattered : v.inscattered;
            const std::array<double, 3>& a = prod ? q.a_shadowed : q.a;
            const std::array<double, 3>& p = prod ? q.p_shadowed : q.p;
            for (int c = 0; c < 3; ++c) fit[c] = r1[c] * DepthFactor(x, DepthExponent(a[c], p[c], theta[e]));
            for (int src = 0; src < 2; ++src) {
              const std::array<double, 3>& m = src ? ev : fit;
              const double err = Dot(y_row, m) / y_ref - 1.0;
              std::array<double, 3> ec;
              for (int c = 0; c < 3; ++c) ec[c] = rc[c] > 0.0 ? m[c] / rc[c] - 1.0 : std::numeric_limits<double>::quiet_NaN();
              ProductAccumulator& A = acc[prod * 2 + src];
              const double elev = render.elevation_deg[e], azd = render.azimuth_deg[az];
              A.all.Add(err, ec, sza, elev, azd, depth_m, x);
              A.all_per_sun[s].Add(err, ec, sza, elev, azd, depth_m, x);
              const bool near = depth_m <= o.near_depth_m, horizon = elev <= o.horizon_elevation_deg;
              if (near) {
                A.near.Add(err, ec, sza, elev, azd, depth_m, x);
                A.near_per_sun[s].Add(err, ec, sza, elev, azd, depth_m, x);
              } else {
                A.far.Add(err, ec, sza, elev, azd, depth_m, x);
              }
              if (horizon) A.horizon.Add(err, ec, sza, elev, azd, depth_m, x);
              if (near && horizon) A.near_horizon.Add(err, ec, sza, elev, azd, depth_m, x);
              if (j + 1 == nx) A.infinite_depth.Add(err, ec, sza, elev, azd, depth_m, x);
              std::vector<float>& map = prod ? (src ? out.residual_shadowed_eval[s] : out.residual_shadowed_fit[s])
                                             : (src ? out.residual_fog_eval[s] : out.residual_fog_fit[s]);
              map[i] = static_cast<float>(err);
              if (prod == 0 && src == 1) {
                out.residual_fog_eval_rgb[s][i] = {static_cast<float>(ec[0]), static_cast<float>(ec[1]), static_cast<float>(ec[2])};
              }
            }
          }
        }
      }
    }
  }
  out.fog_fit = acc[0].Done();
  out.fog_eval = acc[1].Done();
  out.shadowed_fit = acc[2].Done();
  out.shadowed_eval = acc[3].Done();
  out.reference_noise_rms = noise_n ? std::sqrt(noise2 / static_cast<double>(noise_n)) : 0.0;

  // ---- Diagnostics: the fog's fit error (luminance) with other parameter choices on the same
  // samples. `params(s, az, e)` gives (a, p) per channel for table s, azimuth az, elevation e.
  using ParamPair = std::pair<std::array<double, 3>, std::array<double, 3>>;
  auto diagnose = [&](const std::string& name, const std::string& description,
                      const std::function<ParamPair(size_t, size_t, size_t)>& params) {
    Accumulator all, near, horizon;
    for (size_t s = 0; s < n_tab; ++s) {
      const double sza = render.tables[s].sun_zenith_deg;
      for (size_t az = 0; az < na; ++az) {
        for (size_t e = 0; e < ne; ++e) {
          const ParamPair q = params(s, az, e);
          const std::array<double, 3> r1{ref[s][render.TableIndex(e, az, nx - 1) * 3], ref[s][render.TableIndex(e, az, nx - 1) * 3 + 1],
                                         ref[s][render.TableIndex(e, az, nx - 1) * 3 + 2]};
          for (size_t j = 0; j < nx; ++j) {
            const size_t i = render.TableIndex(e, az, j);
            const std::array<double, 3> rc{ref[s][i * 3], ref[s][i * 3 + 1], ref[s][i * 3 + 2]};
            const double y_ref = Dot(y_row, rc);
            if (!(y_ref > 0.0)) continue;
            std::array<double, 3> m;
            for (size_t c = 0; c < 3; ++c) m[c] = r1[c] * DepthFactor(render.depth_x[j], DepthExponent(q.first[c], q.second[c], theta[e]));
            const double err = Dot(y_row, m) / y_ref - 1.0;
            const std::array<double, 3> ec{0, 0, 0};
            const double depth_m = render.depth_x[j] * depth_max[e], elev = render.elevation_deg[e], azd = render.azimuth_deg[az];
            all.Add(err, ec, sza, elev, azd, depth_m, render.depth_x[j]);
            if (depth_m <= o.near_depth_m) near.Add(err, ec, sza, elev, azd, depth_m, render.depth_x[j]);
            if (elev <= o.horizon_elevation_deg) horizon.Add(err, ec, sza, elev, azd, depth_m, render.depth_x[j]);
          }
        }
      }
    }
    out.diagnostics.push_back({name, description, all.Done(), near.Done(), horizon.Done()});
  };
  auto pair_of = [](const std::array<FitResult, 3>& f) {
    return ParamPair{{f[0].a, f[1].a, f[2].a}, {f[0].p, f[1].p, f[2].p}};
  };
  diagnose("global", "one (a, p) per channel for every sun angle (the talk's model), fitted on the fit's tables",
           [&](size_t, size_t, size_t) { return pair_of(out.fit_fog); });
  diagnose("per_table", "(a, p) fitted on each depth table alone (in-sample: the best any per-sun-angle model can do here)",
           [&](size_t s, size_t, size_t) { return pair_of(out.table_fit_fog[s]); });
  {
    std::vector<std::vector<std::array<FitResult, 3>>> per_az(n_tab, std::vector<std::array<FitResult, 3>>(na));
    for (size_t s = 0; s < n_tab; ++s) {
      for (size_t az = 0; az < na; ++az) {
        per_az[s][az] = fit_on(ref, [&](size_t s2, size_t a2, size_t) { return s2 == s && a2 == az; });
      }
    }
    diagnose("per_table_and_azimuth",
             "(a, p) fitted on each depth table and view azimuth alone (in-sample: what an azimuth dimension would add)",
             [&](size_t s, size_t az, size_t) { return pair_of(per_az[s][az]); });
    // k per depth table and elevation (all azimuths): one theta per fit, so p = 0 and k = a.
    std::vector<std::vector<std::array<FitResult, 3>>> per_el(n_tab, std::vector<std::array<FitResult, 3>>(ne));
    for (size_t s = 0; s < n_tab; ++s) {
      for (size_t e = 0; e < ne; ++e) per_el[s][e] = fit_on(ref, [&](size_t s2, size_t, size_t e2) { return s2 == s && e2 == e; });
    }
    diagnose("per_table_and_elevation",
             "k fitted on each depth table and view elevation alone, all azimuths (in-sample: a k table over sun angle x "
             "elevation instead of a theta^p)",
             [&](size_t s, size_t, size_t e) { return pair_of(per_el[s][e]); });
  }

  // Attenuation LUT vs the exact transmittance at the depth tables' points.
  std::array<double, 3> sum2{0, 0, 0};
  size_t n = 0;
  for (size_t e = 0; e < ne; ++e) {
    for (size_t j = 0; j < nx; ++j) {
      const std::array<float, 3> exact = t_rgb(&render.depth_transmittance[(e * nx + j) * nw]);
      const FogValue v = eval.Evaluate(DirOf(render.elevation_deg[e], 0.0), render.depth_x[j] * depth_max[e], 0.0);
      for (int c = 0; c < 3; ++c) {
        const double d = std::fabs(v.transmittance[c] - exact[c]);
        sum2[c] += d * d;
        out.attenuation_max_abs[c] = std::max(out.attenuation_max_abs[c], d);
      }
      ++n;
    }
  }
  for (int c = 0; c < 3; ++c) out.attenuation_rms_abs[c] = std::sqrt(sum2[c] / static_cast<double>(std::max<size_t>(n, 1)));
  return out;
}

// ------------------------------------------------------------------------------------- encoding

namespace {

using Json = nlohmann::ordered_json;

std::string Join(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : " ") + FormatExact(x);
  return s;
}

std::string ModelText(const FogParams& p) {
  return fmt::format(
      "Fog(dir, d) = LUT(dir) (1 - exp(-a theta^p x)) / (1 - exp(-a theta^p)) per Linear Rec.2020 channel, "
      "x = min(d / D, 1), D = distance from the observer to the cut sphere (altitude {} m) along dir, directions below "
      "the horizon clamped to it; theta = {}; a, p {}; docs/fog.md",
      FormatExact(p.cut_altitude_m),
      p.angle == AngleDefinition::kPath ? "(cut - observer altitude) / D (path)" : "elevation / 90 deg (elevation)",
      p.slices.empty()    ? "global (one pair per channel)"
      : p.node_v.empty()  ? "per slice of the fog LUT, blended between slices as the LUT"
                          : "per slice of the fog LUT (a also per elevation node, linear in v = (elevation/90 deg)^(1/2)), "
                            "blended between slices as the LUT");
}

std::string PerSliceText() {
  return "a and p per slice of the fog LUT (row k: slice k, R, G, B): fitted per depth table, ln a and p linear in the "
         "sun zenith angle between the tables, constant beyond the first and the last; the runtime blends rows i and "
         "i + 1 linearly with the LUT's slice weight t (a = (1 - t) a_i + t a_i+1; beyond the last slice the last row); "
         "docs/fog.md";
}

std::string ElevationNodesText() {
  return "a per slice (outer list) and elevation node (inner list: nodes at v = (elevation/90 deg)^(1/2), the depth "
         "tables' elevations) per channel: the depth exponent is k = a(v) theta^p with a linear in v between the nodes "
         "(clamped at the ends) and p the slice's; fitted per depth table and elevation as a = k / theta^p, ln a linear "
         "in the sun zenith angle between the tables; docs/fog.md";
}

ExrImage InspectionImage(int width, int height, const lut::PackedTexture& t, const Provenance& prov, const std::string& quantity) {
  ExrImage img = lut::PackedInspectionImage(
      width, height, t,
      "R, G, B: the packed texels as a shader reads them divided by the scale (physical units, Linear Rec.2020); "
      "input_R/G/B: before packing; clamp_flags: 1 = above the format's largest value, 2 = negative (outside "
      "Rec.2020), 4 = denormal (bit OR)");
  img.strings["skybake.quantity"] = quantity;
  SetProvenance(img, prov);
  return img;
}

Json StatsJson(const ErrorStats& s) {
  return Json{{"samples", s.count},
              {"rms", s.rms},
              {"max", s.max},
              {"channel_rms", {{"R", s.channel_rms[0]}, {"G", s.channel_rms[1]}, {"B", s.channel_rms[2]}}},
              {"max_at",
               {{"sun_zenith_deg", s.max_sun_zenith_deg},
                {"elevation_deg", s.max_elevation_deg},
                {"azimuth_from_sun_deg", s.max_azimuth_deg},
                {"depth_m", s.max_depth_m},
                {"x", s.max_x}}}};
}

Json ProductJson(const ProductStats& p, const FogRender& r) {
  Json j;
  j["all"] = StatsJson(p.all);
  j["near_camera"] = StatsJson(p.near);
  j["far"] = StatsJson(p.far);
  j["horizon"] = StatsJson(p.horizon);
  j["near_camera_at_horizon"] = StatsJson(p.near_horizon);
  j["infinite_depth"] = StatsJson(p.infinite_depth);
  Json per = Json::array();
  for (size_t s = 0; s < r.tables.size(); ++s) {
    per.push_back({{"sun_zenith_deg", r.tables[s].sun_zenith_deg},
                   {"rms", p.all_per_sun[s].rms},
                   {"max", p.all_per_sun[s].max},
                   {"near_camera_rms", p.near_per_sun[s].rms},
                   {"near_camera_max", p.near_per_sun[s].max}});
  }
  j["per_sun"] = per;
  return j;
}

Json FitJson(const std::array<FitResult, 3>& f, bool per_channel) {
  Json j = Json::array();
  for (int c = 0; c < (per_channel ? 3 : 1); ++c) {
    j.push_back({{"channel", per_channel ? std::string(1, "RGB"[c]) : std::string("luminance")},
                 {"a", f[c].a},
                 {"p", f[c].p},
                 {"rms_log_residual", f[c].rms_log},
                 {"samples_used", f[c].used},
                 {"samples_left_out", f[c].rejected},
                 {"evaluations", f[c].evaluations},
                 {"p_fitted", f[c].p_fitted},
                 {"at_bound", f[c].at_bound},
                 {"fallback", f[c].fallback},
                 {"status", f[c].status}});
  }
  return j;
}

Json PackJson(const lut::PackedTexture& t) {
  const lut::PackStats& s = t.stats;
  return Json{{"size", {t.width, t.height, t.depth}},
              {"scale", t.scale},
              {"texels", s.texels},
              {"clamped_above_max", s.clamped_high},
              {"negative_rec2020", s.negative_texels},
              {"denormal", s.denormal_texels},
              {"luminance_relative_error_rms", s.y_rel_rms},
              {"luminance_relative_error_max", s.y_rel_max}};
}

Json ProvenanceJson(const Provenance& p) {
  Json in = Json::array();
  for (const auto& [path, hash] : p.inputs) in.push_back({{"path", path}, {"xxh3", hash}});
  return Json{{"tool", p.tool}, {"version", kVersion}, {"parameters", p.parameters}, {"inputs", in}};
}

// Diverging colours for a relative error: blue (-range) - white (0) - red (+range); grey = excluded.
std::array<uint8_t, 3> Diverging(float e, double range) {
  if (!std::isfinite(e)) return {96, 96, 96};
  const double t = std::clamp(e / range, -1.0, 1.0);
  const double lo[3] = {59, 76, 192}, hi[3] = {180, 4, 38};  // Moreland's cool-warm ends (sRGB codes)
  std::array<uint8_t, 3> c;
  for (int k = 0; k < 3; ++k) {
    const double end = t < 0 ? lo[k] : hi[k];
    c[k] = static_cast<uint8_t>(std::lround(255.0 + (end - 255.0) * std::fabs(t)));
  }
  return c;
}

}  // namespace

std::vector<std::string> FogProductFiles(const std::string& P) {
  return {P + ".json",         P + ".ktx2",          P + "_array.ktx2",          P + ".dds",
          P + "_shadowed.ktx2", P + "_shadowed_array.ktx2", P + "_shadowed.dds", P + "_attenuation.ktx2",
          P + "_attenuation.dds", P + "_params.ktx2", P + ".exr",                P + "_report.json",
          P + "_residuals.exr", P + "_residuals.png"};
}

namespace {

// nlohmann's dump(2) puts every number of an array on its own line; arrays holding only numbers
// are written on one line instead (the per-slice tables would otherwise be 100 KB of indentation).
std::string CompactNumberArrays(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '[') {
      size_t j = i + 1;
      bool numeric = true, any = false;
      while (j < text.size() && text[j] != ']') {
        const char c = text[j];
        if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E') {
          any = true;
        } else if (!(c == ',' || c == ' ' || c == '\n')) {
          numeric = false;
          break;
        }
        ++j;
      }
      if (numeric && any && j < text.size()) {
        out += '[';
        bool space = false;
        for (size_t k = i + 1; k < j; ++k) {
          const char c = text[k];
          if (c == ' ' || c == '\n') continue;
          if (space) out += ' ';
          space = false;
          out += c;
          if (c == ',') space = true;
        }
        out += ']';
        i = j + 1;
        continue;
      }
    }
    out += text[i++];
  }
  return out;
}

// The depth function's parameters as a tiny texture for a shader (docs/fog.md, "Files"):
// R32G32B32A32_SFLOAT (a reaches 1e-5 on a Rayleigh-only sky: below half's normal range), W = 1 + nodes (1 without elevation nodes), H = slices, 2 layers (0 fog, 1
// shadowed fog); texel (0, k) = (p_R, p_G, p_B, 0) of slice k, texel (1 + j, k) = (a_R, a_G, a_B, 1)
// at elevation node j. Global parameters are written as the same row in every slice.
ktx2::Texture ParamsTexture(const FogProducts& p, const std::vector<double>& slice_zenith_deg, const Provenance& prov) {
  const FogParams& par = p.params;
  const size_t n_slices = slice_zenith_deg.size(), nodes = std::max<size_t>(par.node_v.size(), 1);
  std::vector<float> v;
  for (int prod = 0; prod < 2; ++prod) {
    for (size_t k = 0; k < n_slices; ++k) {
      const FogParams::Slice q = par.slices.empty()
                                     ? FogParams::Slice{par.a, par.p, par.a_shadowed, par.p_shadowed, {}, {}}
                                     : par.slices[k];
      const std::array<double, 3>& pp = prod ? q.p_shadowed : q.p;
      for (double x : pp) v.push_back(static_cast<float>(x));
      v.push_back(0.0f);
      const std::vector<std::array<double, 3>>& an = prod ? q.a_shadowed_nodes : q.a_nodes;
      for (size_t j = 0; j < nodes; ++j) {
        const std::array<double, 3>& a = an.empty() ? (prod ? q.a_shadowed : q.a) : an[j];
        for (double x : a) v.push_back(static_cast<float>(x));
        v.push_back(1.0f);
      }
    }
  }
  ktx2::Texture tex;
  tex.format = ktx2::R32G32B32A32Sfloat();
  tex.width = static_cast<uint32_t>(1 + nodes);
  tex.height = static_cast<uint32_t>(n_slices);
  tex.layers = 2;
  tex.data = ktx2::EncodeTexels(tex.format, v);
  ktx2::SetProvenance(tex, prov);
  ktx2::SetString(tex, "KTXorientation", "rd");
  ktx2::SetString(tex, "skybake.basis_sky", p.sky);
  ktx2::SetString(tex, "skybake.quantity",
                  "GT7 fog depth function k = a theta^p per Linear Rec.2020 channel (docs/fog.md): layer 0 the fog, layer 1 "
                  "the shadowed fog; row k = slice k of the fog LUT; texel 0 = (p_R, p_G, p_B, 0), texel 1 + j = (a_R, a_G, "
                  "a_B, 1) at elevation node j (one node: a for every elevation); float32 of the parameter file's doubles");
  std::string nv, sz;
  for (double x : par.node_v) nv += (nv.empty() ? "" : " ") + FormatExact(x);
  for (double x : slice_zenith_deg) sz += (sz.empty() ? "" : " ") + FormatExact(x);
  ktx2::SetString(tex, "skybake.fog.parameters_mode", ParamModeName(p.options.params));
  ktx2::SetString(tex, "skybake.fog.elevation_nodes_v", nv.empty() ? "none" : nv);
  ktx2::SetString(tex, "skybake.slice_zenith_deg", sz);
  ktx2::SetString(tex, "skybake.sampling",
                  "per slice: a linear in v = (elevation/90 deg)^(1/2) between the nodes (uniform in v for the pipeline's "
                  "depth tables: texel coordinate (1 + v (W - 2) + 1/2)/W), clamped at the ends; rows i and i + 1 blended "
                  "with the fog LUT's slice weight t (linear in the sun zenith angle); beyond the last slice the last row");
  return tex;
}

// The residual PNG (docs/fog.md "Outputs"): a title; two panels, "fog" and "shadowed fog", each a
// grid of tiles with one row per depth table (labelled with its sun zenith angle and elevation)
// and one column per view azimuth from the sun (labelled); inside a tile depth samples run to the
// right (nearest at the left) and elevation samples upwards (horizon at the bottom), kPx x kPx
// pixels per sample; at the bottom a key tile with the depth and elevation of its samples, and the
// colour scale (relative luminance error, -10 % blue .. +10 % red, white = 0; grey = excluded).
std::string ResidualPng(const FogRender& r, const FogProducts& p, const Font& font) {
  constexpr int kPx = 5, kGap = 4, kMargin = 10, kLabel = 104, kPanelGap = 24, kTitle = 50, kHeader = 38;
  constexpr double kRange = 0.1;  // full scale: +-10 %
  const Rgb8 bg{32, 32, 32}, ink{232, 232, 232}, dim{170, 170, 170};
  const int nx = static_cast<int>(r.depth_x.size()), ne = static_cast<int>(r.elevation_deg.size());
  const int na = static_cast<int>(r.azimuth_deg.size()), ns = static_cast<int>(r.tables.size());
  const int tile_w = nx * kPx, tile_h = ne * kPx;
  const int panel_w = na * (tile_w + kGap) - kGap;
  const int key_h = std::max(tile_h, 30) + 64;
  const int W = std::max(2 * kMargin + kLabel + 2 * panel_w + kPanelGap, 640);
  const int H = 2 * kMargin + kTitle + kHeader + ns * (tile_h + kGap) + key_h;
  Canvas canvas(W, H, bg);
  auto colour = [&](float e) {
    const auto c = Diverging(e, kRange);
    return Rgb8{c[0], c[1], c[2]};
  };
  auto fit = [&](const std::string& text, double px, int width) {
    while (px > 8.0 && font.Advance(text, px) > width) px -= 0.5;
    return px;
  };
  const std::string t1 = fmt::format("fog-fit residuals of {}: the evaluator on the packed LUTs against the reference fog", p.sky);
  const std::string t2 =
      "Colour: relative luminance error Y_model / Y_reference \u2212 1 (\u00b110 % full scale). Rows: depth tables (sun "
      "angle); columns: view azimuth from the sun; in each tile depth runs right, elevation up (key at the bottom).";
  canvas.Text(font, t1, fit(t1, 15, W - 2 * kMargin), kMargin, kMargin + 15, ink);
  canvas.Text(font, t2, fit(t2, 11, W - 2 * kMargin), kMargin, kMargin + 36, dim);
  const int y_header = kMargin + kTitle, y_tiles = y_header + kHeader;
  const int x_panels = kMargin + kLabel;
  const char* panel_name[2] = {"fog", "shadowed fog"};
  for (int prod = 0; prod < 2; ++prod) {
    const int px0 = x_panels + prod * (panel_w + kPanelGap);
    canvas.Text(font, panel_name[prod], 14, px0 + panel_w / 2, y_header + 14, ink, Align::kCentre);
    canvas.HLine(px0, px0 + panel_w, y_header + 19, dim);
    for (int a = 0; a < na; ++a) {
      const std::string az = (a == 0 ? "azimuth " : "") + FormatLabelNumber(r.azimuth_deg[a], 3) + "\u00b0";
      canvas.Text(font, az, fit(az, 10, tile_w + kGap), px0 + a * (tile_w + kGap) + tile_w / 2, y_header + 33, dim,
                  Align::kCentre);
    }
    const auto& maps = prod ? p.residual_shadowed_eval : p.residual_fog_eval;
    for (int s = 0; s < ns; ++s) {
      for (int a = 0; a < na; ++a) {
        const int x0 = px0 + a * (tile_w + kGap), y0 = y_tiles + s * (tile_h + kGap);
        for (int e = 0; e < ne; ++e) {
          for (int j = 0; j < nx; ++j) {
            canvas.Fill({x0 + j * kPx, y0 + (ne - 1 - e) * kPx, x0 + (j + 1) * kPx, y0 + (ne - e) * kPx},
                        colour(maps[s][r.TableIndex(e, a, j)]));
          }
        }
      }
    }
  }
  for (int s = 0; s < ns; ++s) {
    const double sz = r.tables[s].sun_zenith_deg;
    const int y0 = y_tiles + s * (tile_h + kGap);
    const int mid = y0 + tile_h / 2;
    canvas.Text(font, "sun zenith " + FormatLabelNumber(sz, 4) + "\u00b0", 10.5, kMargin, mid - 1, ink);
    canvas.Text(font, "elevation " + FormatLabelNumber(90.0 - sz, 4) + "\u00b0", 10, kMargin, mid + 11, dim);
    if (s < static_cast<int>(p.table_in_fit.size()) && !p.table_in_fit[s]) {
      canvas.Text(font, "not in the fit", 9, kMargin, mid + 22, dim);
    }
  }

  // Key: one tile with its axes, and the colour scale.
  const int yk = y_tiles + ns * (tile_h + kGap) + 18;
  const int xk = x_panels + 40;
  canvas.Text(font, "key (one tile):", 11, kMargin, yk + tile_h / 2 + 4, ink);
  canvas.Frame({xk - 1, yk - 1, xk + tile_w + 1, yk + tile_h + 1}, dim);
  for (int e = 0; e < ne; ++e) {
    for (int j = 0; j < nx; ++j) {
      const uint8_t g = static_cast<uint8_t>(70 + 120 * ((e + j) % 2));
      canvas.Fill({xk + j * kPx, yk + (ne - 1 - e) * kPx, xk + (j + 1) * kPx, yk + (ne - e) * kPx}, {g, g, g});
    }
  }
  for (int j : {0, nx - 1}) {  // depth ticks under the first and last sample columns
    const int x = xk + j * kPx + kPx / 2;
    canvas.VLine(x, yk + tile_h + 1, yk + tile_h + 5, dim);
    canvas.Text(font, FormatLabelNumber(r.depth_x[j], 2), 9, x, yk + tile_h + 15, dim, Align::kCentre);
  }
  canvas.Text(font,
              fmt::format("depth x \u2192 (fraction of the path to the fog's top at {} m), one column per sample",
                          FormatLabelNumber(r.cut_altitude_m, 4)),
              10, xk, yk + tile_h + 29, dim);
  for (int e : {0, ne - 1}) {  // elevation ticks left of the bottom and top sample rows
    const int y = yk + (ne - 1 - e) * kPx + kPx / 2;
    canvas.HLine(xk - 5, xk - 1, y, dim);
    canvas.Text(font, FormatLabelNumber(r.elevation_deg[e], 3) + "\u00b0", 9, xk - 7, y + 3, dim, Align::kRight);
  }
  canvas.TextUp(font, "elevation \u2192", 9, xk - 30, yk + tile_h / 2, dim, Align::kCentre);

  ScaleBar bar;
  const int xb = xk + tile_w + 160, bar_w = std::min(300, W - kMargin - 20 - xb);
  bar.bar = {xb, yk + 14, xb + std::max(bar_w, 60), yk + 26};
  bar.colour = [&](double f) { return colour(static_cast<float>((2.0 * f - 1.0) * kRange)); };
  for (double v : NiceTicks(-100 * kRange, 100 * kRange, 5)) {
    bar.ticks.push_back({(v / 100 + kRange) / (2 * kRange), (v > 0 ? "+" : "") + FormatLabelNumber(v, 3) + " %"});
  }
  bar.title = "relative luminance error (model / reference \u2212 1)";
  bar.text_px = 10;
  bar.ink = dim;
  DrawScaleBar(canvas, font, bar);
  const int xs = xb, ys = yk + 50;
  canvas.Fill({xs, ys, xs + 12, ys + 10}, colour(std::numeric_limits<float>::quiet_NaN()));
  canvas.Text(font, "no reference (excluded)", 10, xs + 18, ys + 9, dim);
  return canvas.EncodePng();
}

}  // namespace

std::map<std::string, std::string> EncodeFogProducts(const FogRender& r, const FogProducts& p, const std::string& P,
                                                     const Provenance& prov, const Font& font) {
  std::map<std::string, std::string> out;
  const FogGeometry geo = r.geometry();
  // ---- Fog and shadowed fog LUTs: lut-pack's sky texture layout and keys (lut::SkyKtx2), so that
  // lut::SkyLutDecoder reads them; the quantity and the night rule are the fog's.
  lut::LutSet set;
  set.options.night_end_zenith_deg = p.options.night_end_zenith_deg;
  auto fog_ktx2 = [&](const lut::PackedTexture& t, bool shadowed, bool array) {
    lut::SkyLutProduct sp;
    sp.name = p.sky;
    sp.render = &p.layout;
    sp.sky = t;
    sp.night_rgb = {0, 0, 0};
    ktx2::Texture tex = lut::SkyKtx2(set, sp, array, prov);
    ktx2::SetString(tex, "skybake.quantity",
                    std::string(shadowed ? "shadowed fog (no single-scattered sun)" : "fog") +
                        " of the whole low-atmosphere segment (x = 1): in-scattered radiance (cd/m^2 of luminance) in "
                        "Linear Rec.2020, times skybake.scale; texel (x, y, slice) is the direction of the GT7 sphere "
                        "mapping at " +
                        std::string(p.texel_grid == gt7::TexelGrid::kNodes ? "u = x/(W - 1), v = y/(H - 1)" : "u = (x + 1/2)/W, v = (y + 1/2)/H") +
                        " for the sun zenith angle of the slice; directions below the horizon hold the horizon's value");
    ktx2::SetString(tex, "skybake.night",
                    fmt::format("below the last slice (sun zenith {} deg) the decoded fog moves linearly to 0, reached at "
                                "sun zenith {} deg",
                                FormatExact(r.slice_zenith_deg.back()), FormatExact(p.options.night_end_zenith_deg)));
    ktx2::SetString(tex, "skybake.fog.model", ModelText(p.params));
    ktx2::SetString(tex, "skybake.fog.cut_altitude_m", FormatExact(r.cut_altitude_m));
    ktx2::SetString(tex, "skybake.fog.parameters", P + ".json");
    ktx2::SetString(tex, "skybake.fog.parameters_texture", P + "_params.ktx2");
    ktx2::SetString(tex, "skybake.fog.parameters_mode", ParamModeName(p.options.params));
    if (p.texel_grid == gt7::TexelGrid::kNodes) {
      ktx2::SetString(tex, "skybake.texel_grid", gt7::TexelGridName(p.texel_grid));
      ktx2::SetString(tex, "skybake.sphere_mapping", p.layout.sphere.Describe(p.texel_grid));
      ktx2::SetString(tex, "skybake.sampling",
                      "texel (x, y) is the node u = x/(W - 1), v = y/(H - 1) of the sphere mapping: sample at texel "
                      "coordinates ((u (W - 1) + 1/2)/W, (v (H - 1) + 1/2)/H), bilinear, clamp-to-edge; slices as lut-pack's "
                      "sky LUTs: slice coordinate s of the sun zenith theta from the time mapping, slices i = min(floor(s), "
                      "N - 2) and i + 1, each read with its own sphere-mapping family at the target sun zenith (sun-aligned "
                      "slices at min(theta, threshold zenith)), blended geometrically per channel, max(a, 1e-6)^(1 - t) "
                      "max(b, 1e-6)^t with t = (theta - theta_i)/(theta_i+1 - theta_i) (docs/fog.md, docs/lut-pack.md)");
    }
    return ktx2::EncodeKtx2(tex);
  };
  auto dds = [](const lut::PackedTexture& t, bool volume) {
    dds::Texture d;
    d.width = static_cast<uint32_t>(t.width);
    d.height = static_cast<uint32_t>(t.height);
    d.depth = volume ? static_cast<uint32_t>(t.depth) : 0;
    d.data = t.bytes;
    return dds::EncodeDds(d);
  };
  out[P + ".ktx2"] = fog_ktx2(p.fog, false, false);
  out[P + "_array.ktx2"] = fog_ktx2(p.fog, false, true);
  out[P + ".dds"] = dds(p.fog, true);
  out[P + "_shadowed.ktx2"] = fog_ktx2(p.shadowed, true, false);
  out[P + "_shadowed_array.ktx2"] = fog_ktx2(p.shadowed, true, true);
  out[P + "_shadowed.dds"] = dds(p.shadowed, true);
  const std::string att_quantity =
      "transmittance from the observer to normalised depth x along the view, for sunlight, per Linear Rec.2020 channel: "
      "[E0 T]_c / [E0]_c (1), times skybake.scale";
  const std::string att_axes =
      "u = x^(1/3) (x = depth / D, D the distance to the cut sphere), v = (elevation / 90 deg)^(1/2) (below the horizon: "
      "0); texel (i, j) is the node u = i/(W-1), v = j/(H-1): sample at ((u (W-1) + 1/2)/W, (v (H-1) + 1/2)/H), "
      "bilinear, clamp to edge";
  {
    ktx2::Texture tex;
    tex.format = ktx2::B10G11R11UfloatPack32();
    tex.width = static_cast<uint32_t>(p.attenuation.width);
    tex.height = static_cast<uint32_t>(p.attenuation.height);
    ktx2::SetProvenance(tex, prov);
    ktx2::SetString(tex, "KTXorientation", "rd");
    ktx2::SetString(tex, "skybake.basis_sky", p.sky);
    ktx2::SetString(tex, "skybake.quantity", att_quantity);
    ktx2::SetString(tex, "skybake.colorspace", ocio_names::kLinearRec2020);
    ktx2::SetString(tex, "skybake.scale", FormatExact(p.attenuation.scale));
    ktx2::SetString(tex, "skybake.sampling", att_axes);
    ktx2::SetString(tex, "skybake.fog.cut_altitude_m", FormatExact(r.cut_altitude_m));
    ktx2::SetString(tex, "skybake.fog.observer_altitude_m", FormatExact(r.observer_altitude_m));
    ktx2::SetString(tex, "skybake.fog.planet_radius_m", FormatExact(r.planet_radius_m));
    tex.data = p.attenuation.bytes;
    out[P + "_attenuation.ktx2"] = ktx2::EncodeKtx2(tex);
  }
  out[P + "_attenuation.dds"] = dds(p.attenuation, false);
  out[P + "_params.ktx2"] = ktx2::EncodeKtx2(ParamsTexture(p, r.slice_zenith_deg, prov));

  // ---- Inspection EXR.
  {
    std::vector<ExrPart> parts;
    const std::string layout = fmt::format("{} slices of {}x{} stacked top to bottom", p.fog.depth, p.fog.width, p.fog.height);
    ExrImage f = InspectionImage(p.fog.width, p.fog.height * p.fog.depth, p.fog, prov, "fog LUT (x = 1), cd/m^2");
    f.strings["skybake.layout"] = layout;
    f.strings["skybake.slice_zenith_deg"] = Join(r.slice_zenith_deg);
    ExrImage s = InspectionImage(p.shadowed.width, p.shadowed.height * p.shadowed.depth, p.shadowed, prov,
                                 "shadowed fog LUT (x = 1), cd/m^2");
    s.strings["skybake.layout"] = layout;
    s.strings["skybake.slice_zenith_deg"] = Join(r.slice_zenith_deg);
    ExrImage a = InspectionImage(p.attenuation.width, p.attenuation.height, p.attenuation, prov, att_quantity);
    a.strings["skybake.sampling"] = att_axes;
    parts.push_back({"fog", std::move(f)});
    parts.push_back({"shadowed", std::move(s)});
    parts.push_back({"attenuation", std::move(a)});
    out[P + ".exr"] = EncodeExrParts(parts);
  }

  // ---- Parameters.
  {
    Json j;
    j["basis_sky"] = p.sky;
    Json m;
    m["equation"] = ModelText(p.params);
    m["angle"] = AngleDefinitionName(p.params.angle);
    m["channels"] = p.options.per_channel ? "rgb (one a, p per Linear Rec.2020 channel)" : "luminance (one a, p for R, G, B)";
    m["colorspace"] = ocio_names::kLinearRec2020;
    m["planet_radius_m"] = p.params.planet_radius_m;
    m["observer_altitude_m"] = p.params.observer_altitude_m;
    m["cut_altitude_m"] = p.params.cut_altitude_m;
    m["boundary_distance_zenith_m"] = geo.BoundaryDistanceM(1.0);
    m["boundary_distance_horizon_m"] = geo.BoundaryDistanceM(0.0);
    m["units"] = "a, p, x and theta are dimensionless; depths in m; LUT radiance in cd/m^2 (Linear Rec.2020)";
    m["parameters"] = ParamModeName(p.options.params);
    m["fog"] = {{"a", p.params.a}, {"p", p.params.p}};
    m["shadowed"] = {{"a", p.params.a_shadowed}, {"p", p.params.p_shadowed}};
    if (!p.params.slices.empty()) {
      Json fa = Json::array(), fp = Json::array(), sa = Json::array(), sp = Json::array();
      for (const FogParams::Slice& q : p.params.slices) {
        fa.push_back(q.a);
        fp.push_back(q.p);
        sa.push_back(q.a_shadowed);
        sp.push_back(q.p_shadowed);
      }
      m["per_slice"] = {{"description", PerSliceText()},
                        {"sun_zenith_deg", r.slice_zenith_deg},
                        {"fog", {{"a", fa}, {"p", fp}}},
                        {"shadowed", {{"a", sa}, {"p", sp}}}};
      if (!p.params.node_v.empty()) {
        Json ea = Json::array(), esa = Json::array();
        for (const FogParams::Slice& q : p.params.slices) {
          ea.push_back(q.a_nodes);
          esa.push_back(q.a_shadowed_nodes);
        }
        std::vector<double> el;
        for (double v : p.params.node_v) el.push_back(90.0 * v * v);
        m["per_slice"]["elevation_nodes"] = {{"description", ElevationNodesText()},
                                             {"v", p.params.node_v},
                                             {"elevation_deg", el},
                                             {"fog", {{"a", ea}}},
                                             {"shadowed", {{"a", esa}}}};
      }
    }
    j["model"] = m;
    j["files"] = {{"fog", P + ".ktx2"},
                  {"fog_array", P + "_array.ktx2"},
                  {"fog_dds", P + ".dds"},
                  {"shadowed", P + "_shadowed.ktx2"},
                  {"shadowed_array", P + "_shadowed_array.ktx2"},
                  {"shadowed_dds", P + "_shadowed.dds"},
                  {"attenuation", P + "_attenuation.ktx2"},
                  {"attenuation_dds", P + "_attenuation.dds"},
                  {"parameters_texture", P + "_params.ktx2"},
                  {"report", P + "_report.json"}};
    j["skybake"] = ProvenanceJson(prov);
    out[P + ".json"] = CompactNumberArrays(j.dump(2)) + "\n";
  }

  // ---- Report.
  {
    Json j;
    j["basis_sky"] = p.sky;
    j["reference"] = {{"file", r.path},
                      {"method", r.method},
                      {"method_settings", r.method_description},
                      {"sun_zenith_deg", [&] {
                         std::vector<double> v;
                         for (const FogDepthTable& t : r.tables) v.push_back(t.sun_zenith_deg);
                         return v;
                       }()},
                      {"elevation_deg", r.elevation_deg},
                      {"azimuth_from_sun_deg", r.azimuth_deg},
                      {"depth_x", r.depth_x},
                      {"noise_rms_relative", p.reference_noise_rms},
                      {"samples_with_zero_fog", p.excluded_samples}};
    j["definitions"] = {
        {"error", "relative luminance error Y_model / Y_reference - 1 (Y from Linear Rec.2020 by OCIO); channel_rms: the "
                  "same per Rec.2020 channel"},
        {"fit", "the model with the exact reference at x = 1: LUT(dir) = Fog_ref(dir, 1), and the (a, p) the evaluator uses "
                "at the table's sun angle (the depth function's error)"},
        {"evaluator", "fog/fog_evaluator.h on the packed textures: mappings, slice interpolation, R11G11B10F and the depth "
                      "function (what a game gets)"},
        {"near_camera", fmt::format("depth <= {} m", FormatExact(p.options.near_depth_m))},
        {"horizon", fmt::format("elevation <= {} deg", FormatExact(p.options.horizon_elevation_deg))},
        {"infinite_depth", "x = 1: the LUT against the direct render of the same directions (consistency)"}};
    Json tables = Json::array();
    for (size_t s = 0; s < r.tables.size(); ++s) {
      tables.push_back({{"sun_zenith_deg", r.tables[s].sun_zenith_deg},
                        {"used_by_the_fit", static_cast<bool>(p.table_in_fit[s])},
                        {"fog", FitJson(p.table_fit_fog[s], p.options.per_channel)},
                        {"shadowed", FitJson(p.table_fit_shadowed[s], p.options.per_channel)}});
    }
    j["fit"] = {{"angle", AngleDefinitionName(p.params.angle)},
                {"parameters", ParamModeName(p.options.params)},
                {"fog", FitJson(p.fit_fog, p.options.per_channel)},
                {"shadowed", FitJson(p.fit_shadowed, p.options.per_channel)},
                {"per_table", tables}};
    Json diag = Json::array();
    for (const FitDiagnostic& d : p.diagnostics) {
      diag.push_back({{"name", d.name}, {"description", d.description}, {"all", StatsJson(d.all)},
                      {"near_camera", StatsJson(d.near)}, {"horizon", StatsJson(d.horizon)}});
    }
    j["fit_diagnostics"] = diag;
    j["errors"] = {{"fog", {{"fit", ProductJson(p.fog_fit, r)}, {"evaluator", ProductJson(p.fog_eval, r)}}},
                   {"shadowed", {{"fit", ProductJson(p.shadowed_fit, r)}, {"evaluator", ProductJson(p.shadowed_eval, r)}}}};
    j["attenuation"] = {{"rms_abs", {{"R", p.attenuation_rms_abs[0]}, {"G", p.attenuation_rms_abs[1]}, {"B", p.attenuation_rms_abs[2]}}},
                        {"max_abs", {{"R", p.attenuation_max_abs[0]}, {"G", p.attenuation_max_abs[1]}, {"B", p.attenuation_max_abs[2]}}}};
    j["packing"] = {{"fog", PackJson(p.fog)}, {"shadowed", PackJson(p.shadowed)}, {"attenuation", PackJson(p.attenuation)}};
    j["skybake"] = ProvenanceJson(prov);
    out[P + "_report.json"] = CompactNumberArrays(j.dump(2)) + "\n";
  }

  // ---- Residual maps.
  {
    std::vector<ExrPart> parts;
    const ExrAxis dx{"depth_x", "1", "normalised depth x", r.depth_x};
    const ExrAxis az{"azimuth", "deg", "view azimuth from the sun", r.azimuth_deg};
    const ExrAxis el{"elevation", "deg", "view elevation", r.elevation_deg};
    for (size_t s = 0; s < r.tables.size(); ++s) {
      ExrTable t;
      t.axes = {dx, az, el};
      t.channels = {"fog_fit_Y", "fog_eval_Y", "shadowed_fit_Y", "shadowed_eval_Y", "fog_eval_R", "fog_eval_G", "fog_eval_B", "depth_m"};
      t.channel_units = {"1", "1", "1", "1", "1", "1", "1", "m"};
      const size_t n = p.residual_fog_fit[s].size();
      for (size_t i = 0; i < n; ++i) {
        const size_t e = i / (r.azimuth_deg.size() * r.depth_x.size()), j = i % r.depth_x.size();
        const double depth = r.depth_x[j] * geo.BoundaryDistanceM(std::sin(r.elevation_deg[e] * kDeg));
        for (float v : {p.residual_fog_fit[s][i], p.residual_fog_eval[s][i], p.residual_shadowed_fit[s][i],
                        p.residual_shadowed_eval[s][i], p.residual_fog_eval_rgb[s][i][0], p.residual_fog_eval_rgb[s][i][1],
                        p.residual_fog_eval_rgb[s][i][2], static_cast<float>(depth)}) {
          t.values.push_back(v);
        }
      }
      ExrImage img = TableToImage(t);
      img.strings["skybake.quantity"] =
          "relative error of the fog model vs the reference (Y_model / Y_ref - 1; NaN where the reference is 0): fit = "
          "exact LUT x depth function, eval = the evaluator on the packed textures";
      img.doubles["skybake.sun_zenith_deg"] = r.tables[s].sun_zenith_deg;
      SetProvenance(img, prov);
      parts.push_back({fmt::format("residual.sza_{:06.2f}", r.tables[s].sun_zenith_deg), std::move(img)});
    }
    out[P + "_residuals.exr"] = EncodeExrParts(parts);

    out[P + "_residuals.png"] = ResidualPng(r, p, font);
  }
  return out;
}

}  // namespace skybake::fog
