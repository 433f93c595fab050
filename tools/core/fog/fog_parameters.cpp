#include "fog/fog_parameters.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "io/error.h"
#include "io/yaml.h"

namespace skybake::fog {

namespace {

// The depth tables the fit uses: those at --fit-sun-zenith-deg, or every table.
void SelectFitTables(const FogRender& render, const FogFitOptions& o, std::vector<bool>* table_in_fit) {
  const size_t n_tab = render.tables.size();
  table_in_fit->assign(n_tab, o.fit_sun_zenith_deg.empty());
  for (double z : o.fit_sun_zenith_deg) {
    bool found = false;
    for (size_t s = 0; s < n_tab; ++s) {
      if (std::fabs(render.tables[s].sun_zenith_deg - z) <= 1e-9) {
        (*table_in_fit)[s] = true;
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
  SKYBAKE_CHECK(std::count(table_in_fit->begin(), table_in_fit->end(), true) > 0);
}

void AsParams(const std::array<FitResult, 3>& f, std::array<double, 3>* a, std::array<double, 3>* p) {
  for (size_t c = 0; c < 3; ++c) {
    (*a)[c] = f[c].a;
    (*p)[c] = f[c].p;
  }
}

// Per slice, ln a and p are piecewise linear in the sun zenith angle between the selected tables
// whose fit had samples (sorted by angle), constant beyond the first and the last: (table lo,
// table hi, weight of hi) at `sza`, or nullopt without usable tables.
std::optional<std::tuple<size_t, size_t, double>> SliceWeights(const FogRender& render, const std::vector<bool>& table_in_fit,
                                                              const std::vector<std::array<FitResult, 3>>& fits, double sza) {
  std::vector<std::pair<double, size_t>> nodes;
  for (size_t s = 0; s < render.tables.size(); ++s) {
    if (table_in_fit[s] && fits[s][0].used > 0 && fits[s][1].used > 0 && fits[s][2].used > 0) {
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
}

// Per slice and elevation: for each selected table s and fit elevation e, k fitted on that
// elevation alone (all azimuths; one theta, so the fit's a is k), stored as a_se = k / theta_e^p_s
// with the table's own p: a_se = a_s reproduces the per-slice model, and theta^p keeps the fast
// variation of k near the horizon out of the interpolation in v. Result [product][table][node].
std::array<std::vector<std::vector<std::array<double, 3>>>, 2> ElevationNodeA(const FogReference& ref, const FogProducts& out,
                                                                              const std::vector<size_t>& nodes_e) {
  std::array<std::vector<std::vector<std::array<double, 3>>>, 2> a_se;
  a_se[0].resize(ref.n_tab);
  a_se[1].resize(ref.n_tab);
  for (size_t s = 0; s < ref.n_tab; ++s) {
    if (!out.table_in_fit[s]) continue;
    for (int prod = 0; prod < 2; ++prod) {
      const std::array<FitResult, 3>& table = prod ? out.table_fit_shadowed[s] : out.table_fit_fog[s];
      auto& dst = a_se[static_cast<size_t>(prod)][s];
      for (size_t e : nodes_e) {
        const std::array<FitResult, 3> k = FitOn(ref, ref.Product(prod), [&](size_t s2, size_t, size_t e2) { return s2 == s && e2 == e; });
        std::array<double, 3> v{};
        for (size_t c = 0; c < 3; ++c) {
          // No usable sample at this elevation: the table's own a.
          v[c] = k[c].used > 0 ? k[c].a / DepthExponent(1.0, table[c].p, ref.theta[e]) : table[c].a;
        }
        dst.push_back(v);
      }
    }
  }
  return a_se;
}

// (a, p) per slice of the fog LUT (and a per elevation node in kPerSliceElevation), interpolated
// between the depth tables' fits; slices without a usable table take the global fit.
void FitPerSlice(const FogReference& ref, FogProducts* out) {
  const FogRender& render = *ref.render;
  const FogFitOptions& o = *ref.options;
  FogParams& par = out->params;
  std::vector<size_t> nodes_e;
  for (size_t e = 0; e < ref.ne; ++e) {
    if (out->elevation_in_fit[e]) nodes_e.push_back(e);
  }
  std::array<std::vector<std::vector<std::array<double, 3>>>, 2> a_se;
  if (o.params == ParamMode::kPerSliceElevation) {
    for (size_t e : nodes_e) par.node_v.push_back(AttenuationV(ref.mu[e]));
    a_se = ElevationNodeA(ref, *out, nodes_e);
  }
  for (double sza : render.slice_zenith_deg) {
    FogParams::Slice q;
    for (int prod = 0; prod < 2; ++prod) {
      const std::vector<std::array<FitResult, 3>>& fits = prod ? out->table_fit_shadowed : out->table_fit_fog;
      const std::array<FitResult, 3>& global = prod ? out->fit_shadowed : out->fit_fog;
      std::array<double, 3>& a = prod ? q.a_shadowed : q.a;
      std::array<double, 3>& p = prod ? q.p_shadowed : q.p;
      std::vector<std::array<double, 3>>& an = prod ? q.a_shadowed_nodes : q.a_nodes;
      const auto wt = SliceWeights(render, out->table_in_fit, fits, sza);
      if (!wt) {
        AsParams(global, &a, &p);
        if (o.params == ParamMode::kPerSliceElevation) an.assign(nodes_e.size(), a);
        continue;
      }
      const auto [lo, hi, w] = *wt;
      for (size_t c = 0; c < 3; ++c) {
        a[c] = std::exp((1 - w) * std::log(fits[lo][c].a) + w * std::log(fits[hi][c].a));
        p[c] = (1 - w) * fits[lo][c].p + w * fits[hi][c].p;
      }
      if (o.params == ParamMode::kPerSliceElevation) {
        const auto& A = a_se[static_cast<size_t>(prod)];
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

}  // namespace

void FitFogParameters(const FogReference& ref, const std::string& sky, FogProducts* out) {
  const FogRender& render = *ref.render;
  const FogFitOptions& o = *ref.options;
  SelectFitTables(render, o, &out->table_in_fit);
  FogParams& par = out->params;
  par.basis_sky = sky;
  par.angle = o.angle;
  par.planet_radius_m = render.planet_radius_m;
  par.observer_altitude_m = render.observer_altitude_m;
  par.cut_altitude_m = render.cut_altitude_m;
  // Elevations the fits use: every fit_elevation_stride-th row of the tables, and the last.
  SKYBAKE_CHECK(o.fit_elevation_stride >= 1);
  out->elevation_in_fit.assign(ref.ne, false);
  for (size_t e = 0; e < ref.ne; e += static_cast<size_t>(o.fit_elevation_stride)) out->elevation_in_fit[e] = true;
  out->elevation_in_fit[ref.ne - 1] = true;
  auto in_fit = [&](size_t s, size_t e) { return out->table_in_fit[s] && out->elevation_in_fit[e]; };
  out->fit_fog = FitOn(ref, ref.fog, [&](size_t s, size_t, size_t e) { return in_fit(s, e); });
  out->fit_shadowed = FitOn(ref, ref.shadowed, [&](size_t s, size_t, size_t e) { return in_fit(s, e); });
  AsParams(out->fit_fog, &par.a, &par.p);
  AsParams(out->fit_shadowed, &par.a_shadowed, &par.p_shadowed);
  // Per depth table (the diagnostics use every table; the per-slice parameters the selected ones).
  out->table_fit_fog.resize(ref.n_tab);
  out->table_fit_shadowed.resize(ref.n_tab);
  for (size_t s = 0; s < ref.n_tab; ++s) {
    out->table_fit_fog[s] = FitOn(ref, ref.fog, [&](size_t s2, size_t, size_t e) { return s2 == s && out->elevation_in_fit[e]; });
    out->table_fit_shadowed[s] = FitOn(ref, ref.shadowed, [&](size_t s2, size_t, size_t e) { return s2 == s && out->elevation_in_fit[e]; });
  }
  if (o.params != ParamMode::kGlobal) FitPerSlice(ref, out);
}

}  // namespace skybake::fog
