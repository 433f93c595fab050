#include "fog/fog_errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace skybake::fog {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

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

// One sample's error (relative luminance `err`, per channel `ec`) added to every subset it is in.
struct Sample {
  size_t table;
  double sza, elev, az, depth_m, x;
  bool last_depth;
};

void AddToSubsets(ProductAccumulator& A, const Sample& q, double err, const std::array<double, 3>& ec, const FogFitOptions& o) {
  A.all.Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
  A.all_per_sun[q.table].Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
  const bool near = q.depth_m <= o.near_depth_m, horizon = q.elev <= o.horizon_elevation_deg;
  if (near) {
    A.near.Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
    A.near_per_sun[q.table].Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
  } else {
    A.far.Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
  }
  if (horizon) A.horizon.Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
  if (near && horizon) A.near_horizon.Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
  if (q.last_depth) A.infinite_depth.Add(err, ec, q.sza, q.elev, q.az, q.depth_m, q.x);
}

}  // namespace

// The loop visits every (table, elevation, azimuth, depth) sample once, evaluating the model
// both ways for both products; a function per product would evaluate the evaluator twice.
void MeasureFogErrors(const FogReference& ref, const FogEvaluator& eval, FogProducts* out) {
  const FogRender& render = *ref.render;
  const FogFitOptions& o = *ref.options;
  const size_t n_tab = ref.n_tab, ne = ref.ne, na = ref.na, nx = ref.nx;
  ProductAccumulator acc[4];  // fog fit, fog eval, shadowed fit, shadowed eval
  for (ProductAccumulator& a : acc) {
    a.near_per_sun.resize(n_tab);
    a.all_per_sun.resize(n_tab);
  }
  out->residual_fog_fit.assign(n_tab, std::vector<float>(ne * na * nx, kNaN));
  out->residual_fog_eval = out->residual_shadowed_fit = out->residual_shadowed_eval = out->residual_fog_fit;
  out->residual_fog_eval_rgb.assign(n_tab, std::vector<std::array<float, 3>>(ne * na * nx, {kNaN, kNaN, kNaN}));
  double noise2 = 0.0;
  size_t noise_n = 0;
  for (size_t s = 0; s < n_tab; ++s) {
    const double sza = render.tables[s].sun_zenith_deg;
    for (size_t e = 0; e < ne; ++e) {
      const FogParams::Slice q = eval.ParamsAt(sza * kDeg, ref.mu[e]);  // what the evaluator uses at this sun angle and elevation
      for (size_t az = 0; az < na; ++az) {
        const std::array<double, 3> dir = DirOf(render.elevation_deg[e], render.azimuth_deg[az]);
        const size_t i1 = render.TableIndex(e, az, nx - 1);
        for (size_t j = 0; j < nx; ++j) {
          const size_t i = render.TableIndex(e, az, j);
          const double x = render.depth_x[j];
          const double depth_m = x * ref.depth_max[e];
          const FogValue v = eval.Evaluate(dir, j + 1 == nx ? ref.depth_max[e] * 2.0 : depth_m, sza * kDeg, 0.0);
          const FogValue vs = eval.Evaluate(dir, j + 1 == nx ? ref.depth_max[e] * 2.0 : depth_m, sza * kDeg, 1.0);
          const Sample sample{s, sza, render.elevation_deg[e], render.azimuth_deg[az], depth_m, x, j + 1 == nx};
          for (int prod = 0; prod < 2; ++prod) {
            const std::vector<float>& d = ref.Product(prod)[s];
            const std::array<double, 3> rc{d[i * 3], d[i * 3 + 1], d[i * 3 + 2]};
            const std::array<double, 3> r1{d[i1 * 3], d[i1 * 3 + 1], d[i1 * 3 + 2]};
            const double y_ref = Dot(ref.y_row, rc);
            if (!(y_ref > 0.0)) {
              if (prod == 0) ++out->excluded_samples;
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
            for (int c = 0; c < 3; ++c) fit[c] = r1[c] * DepthFactor(x, DepthExponent(a[c], p[c], ref.theta[e]));
            for (int src = 0; src < 2; ++src) {
              const std::array<double, 3>& m = src ? ev : fit;
              const double err = Dot(ref.y_row, m) / y_ref - 1.0;
              std::array<double, 3> ec;
              for (int c = 0; c < 3; ++c) ec[c] = rc[c] > 0.0 ? m[c] / rc[c] - 1.0 : std::numeric_limits<double>::quiet_NaN();
              AddToSubsets(acc[prod * 2 + src], sample, err, ec, o);
              std::vector<float>& map = prod ? (src ? out->residual_shadowed_eval[s] : out->residual_shadowed_fit[s])
                                             : (src ? out->residual_fog_eval[s] : out->residual_fog_fit[s]);
              map[i] = static_cast<float>(err);
              if (prod == 0 && src == 1) {
                out->residual_fog_eval_rgb[s][i] = {static_cast<float>(ec[0]), static_cast<float>(ec[1]), static_cast<float>(ec[2])};
              }
            }
          }
        }
      }
    }
  }
  out->fog_fit = acc[0].Done();
  out->fog_eval = acc[1].Done();
  out->shadowed_fit = acc[2].Done();
  out->shadowed_eval = acc[3].Done();
  out->reference_noise_rms = noise_n ? std::sqrt(noise2 / static_cast<double>(noise_n)) : 0.0;
}

namespace {

// (a, p) per channel for table s, azimuth az, elevation e.
using ParamPair = std::pair<std::array<double, 3>, std::array<double, 3>>;
using ParamsOf = std::function<ParamPair(size_t, size_t, size_t)>;

ParamPair PairOf(const std::array<FitResult, 3>& f) { return ParamPair{{f[0].a, f[1].a, f[2].a}, {f[0].p, f[1].p, f[2].p}}; }

FitDiagnostic Diagnose(const FogReference& ref, const std::string& name, const std::string& description, const ParamsOf& params) {
  const FogRender& render = *ref.render;
  const FogFitOptions& o = *ref.options;
  const size_t nx = ref.nx;
  Accumulator all, near, horizon;
  for (size_t s = 0; s < ref.n_tab; ++s) {
    const double sza = render.tables[s].sun_zenith_deg;
    const std::vector<float>& d = ref.fog[s];
    for (size_t az = 0; az < ref.na; ++az) {
      for (size_t e = 0; e < ref.ne; ++e) {
        const ParamPair q = params(s, az, e);
        const std::array<double, 3> r1{d[render.TableIndex(e, az, nx - 1) * 3], d[render.TableIndex(e, az, nx - 1) * 3 + 1],
                                       d[render.TableIndex(e, az, nx - 1) * 3 + 2]};
        for (size_t j = 0; j < nx; ++j) {
          const size_t i = render.TableIndex(e, az, j);
          const std::array<double, 3> rc{d[i * 3], d[i * 3 + 1], d[i * 3 + 2]};
          const double y_ref = Dot(ref.y_row, rc);
          if (!(y_ref > 0.0)) continue;
          std::array<double, 3> m;
          for (size_t c = 0; c < 3; ++c) m[c] = r1[c] * DepthFactor(render.depth_x[j], DepthExponent(q.first[c], q.second[c], ref.theta[e]));
          const double err = Dot(ref.y_row, m) / y_ref - 1.0;
          const std::array<double, 3> ec{0, 0, 0};
          const double depth_m = render.depth_x[j] * ref.depth_max[e], elev = render.elevation_deg[e], azd = render.azimuth_deg[az];
          all.Add(err, ec, sza, elev, azd, depth_m, render.depth_x[j]);
          if (depth_m <= o.near_depth_m) near.Add(err, ec, sza, elev, azd, depth_m, render.depth_x[j]);
          if (elev <= o.horizon_elevation_deg) horizon.Add(err, ec, sza, elev, azd, depth_m, render.depth_x[j]);
        }
      }
    }
  }
  return {name, description, all.Done(), near.Done(), horizon.Done()};
}

}  // namespace

void AddFitDiagnostics(const FogReference& ref, FogProducts* out) {
  const size_t n_tab = ref.n_tab, na = ref.na, ne = ref.ne;
  out->diagnostics.push_back(Diagnose(ref, "global",
                                      "one (a, p) per channel for every sun angle (the talk's model), fitted on the fit's tables",
                                      [&](size_t, size_t, size_t) { return PairOf(out->fit_fog); }));
  out->diagnostics.push_back(
      Diagnose(ref, "per_table", "(a, p) fitted on each depth table alone (in-sample: the best any per-sun-angle model can do here)",
               [&](size_t s, size_t, size_t) { return PairOf(out->table_fit_fog[s]); }));
  std::vector<std::vector<std::array<FitResult, 3>>> per_az(n_tab, std::vector<std::array<FitResult, 3>>(na));
  for (size_t s = 0; s < n_tab; ++s) {
    for (size_t az = 0; az < na; ++az) {
      per_az[s][az] = FitOn(ref, ref.fog, [&](size_t s2, size_t a2, size_t) { return s2 == s && a2 == az; });
    }
  }
  out->diagnostics.push_back(Diagnose(ref, "per_table_and_azimuth",
                                      "(a, p) fitted on each depth table and view azimuth alone (in-sample: what an azimuth "
                                      "dimension would add)",
                                      [&](size_t s, size_t az, size_t) { return PairOf(per_az[s][az]); }));
  // k per depth table and elevation (all azimuths): one theta per fit, so p = 0 and k = a.
  std::vector<std::vector<std::array<FitResult, 3>>> per_el(n_tab, std::vector<std::array<FitResult, 3>>(ne));
  for (size_t s = 0; s < n_tab; ++s) {
    for (size_t e = 0; e < ne; ++e) per_el[s][e] = FitOn(ref, ref.fog, [&](size_t s2, size_t, size_t e2) { return s2 == s && e2 == e; });
  }
  out->diagnostics.push_back(Diagnose(ref, "per_table_and_elevation",
                                      "k fitted on each depth table and view elevation alone, all azimuths (in-sample: a k "
                                      "table over sun angle x elevation instead of a theta^p)",
                                      [&](size_t s, size_t, size_t e) { return PairOf(per_el[s][e]); }));
}

void MeasureAttenuation(const FogReference& ref, const FogEvaluator& eval, const SunlightTransmittance& sunlight,
                        FogProducts* out) {
  const FogRender& render = *ref.render;
  const size_t nw = sunlight.wavelengths();
  std::array<double, 3> sum2{0, 0, 0};
  size_t n = 0;
  for (size_t e = 0; e < ref.ne; ++e) {
    for (size_t j = 0; j < ref.nx; ++j) {
      const std::array<float, 3> exact = sunlight(&render.depth_transmittance[(e * ref.nx + j) * nw]);
      const FogValue v = eval.Evaluate(DirOf(render.elevation_deg[e], 0.0), render.depth_x[j] * ref.depth_max[e], 0.0);
      for (int c = 0; c < 3; ++c) {
        const double d = std::fabs(v.transmittance[c] - exact[c]);
        sum2[c] += d * d;
        out->attenuation_max_abs[c] = std::max(out->attenuation_max_abs[c], d);
      }
      ++n;
    }
  }
  for (int c = 0; c < 3; ++c) out->attenuation_rms_abs[c] = std::sqrt(sum2[c] / static_cast<double>(std::max<size_t>(n, 1)));
}

}  // namespace skybake::fog
