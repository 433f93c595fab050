#include "transport/budget.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "color/color.h"
#include "io/error.h"
#include "io/text_list.h"
#include "transport/sky_method.h"

namespace skybake {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
using Sky = ChartSky;  // observer XYZ per direction

struct Evaluator {
  const BudgetOptions& o;
  const SkyDirections& D;
  // Skies at every sun angle for a scene, an orders cap and an observer altitude; returns seconds.
  double Render(const Scene& sc, int orders, const std::vector<double>& altitudes, std::vector<std::vector<Sky>>* out,
                std::string* description = nullptr) const {
    SkyMethodOptions mo;
    mo.quality = o.quality;
    mo.orders = orders;
    return RenderChartSkies(sc, o.method, mo, altitudes, o.sun_zenith_deg, D, out, description);
  }
};

}  // namespace

double RenderChartSkies(const Scene& sc, const std::string& name, const SkyMethodOptions& options,
                        const std::vector<double>& altitudes, const std::vector<double>& sun_zenith_deg, const SkyDirections& D,
                        std::vector<std::vector<ChartSky>>* out, std::string* description) {
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<SkyMethod> method = MakeSkyMethod(name, sc.model, options, {});
  if (description) *description = method->Describe();
  out->assign(altitudes.size(), std::vector<ChartSky>(sun_zenith_deg.size()));
  const size_t n = altitudes.size() * sun_zenith_deg.size();
  tbb::parallel_for(size_t{0}, n, size_t{1}, [&](size_t k) {
    const size_t a = k / sun_zenith_deg.size(), s = k % sun_zenith_deg.size();
    std::vector<double> L;
    method->Radiance(altitudes[a], sun_zenith_deg[s] * kDeg, D.dirs, &L);
    (*out)[a][s] = SpectralToXyz(L, sc.xyz_weights);
  });
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double ParseTolerance(const std::string& text, const std::string& option) {
  std::string t;
  for (char c : text) {
    if (c != ' ') t += c;
  }
  double scale = 1.0;
  if (!t.empty() && t.back() == '%') {
    scale = 0.01;
    t.pop_back();
  }
  double v = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size() || !(v > 0.0) || !std::isfinite(v)) {
    throw UsageError(option + ": expected a positive number or percentage (e.g. 1% or 0.01), got '" + text + "'");
  }
  return v * scale;
}

BudgetReport RunBudget(const SceneOptions& so, const BudgetOptions& o, const ProgressFn& progress) {
  if (o.criterion != "rms" && o.criterion != "max") throw UsageError("--criterion: expected rms or max, got '" + o.criterion + "'");
  if (!(o.tolerance > 0.0)) throw UsageError("--tolerance: must be > 0");
  if (o.sun_zenith_deg.empty()) throw UsageError("--sun-zenith-deg: at least one angle");
  for (double z : o.sun_zenith_deg) {
    if (!(z >= 0.0 && z <= 180.0)) throw UsageError(fmt::format("--sun-zenith-deg: {} is outside 0-180", z));
  }
  if (!FindSkyMethod(o.method)) {
    throw UsageError("--method: the budget needs a deterministic method (" + TextList(SkyMethodNames(), ", ") +
                     "), got '" + o.method + "'");
  }
  ReportProgress(progress, "budget: baseline", 0.0);
  const Scene base = LoadScene(so, {});
  const double top = base.model.altitude_m.back();
  const double alt0 = base.spec.observer_altitude_m;
  const double lo = o.altitude_lo_m >= 0.0 ? o.altitude_lo_m : alt0;
  const double hi = o.altitude_hi_m >= 0.0 ? o.altitude_hi_m : alt0 + 300.0;
  if (!(hi >= lo) || hi >= top) {
    throw UsageError(fmt::format("--altitude-range-m: expected lo:hi with 0 <= lo <= hi < {} m (the top), got {}:{}", top, lo, hi));
  }
  const SkyDirections D = ChartDirections();
  const ColorConfig config = ColorConfig::Load(base.ocio_config);
  const ColorProcessor to2020 = config.Converter(XyzColorSpace(base.observer), ocio_names::kLinearRec2020);
  const ColorProcessor toref = config.Converter(XyzColorSpace(base.observer), ocio_names::kCieXyzD65);
  const Evaluator ev{o, D};

  BudgetReport rep;
  rep.tolerance = o.tolerance;
  rep.criterion = o.criterion;
  rep.baseline_wavelengths = base.grid.size();
  rep.files_read = base.files_read;
  std::vector<std::vector<Sky>> base_sky;
  rep.baseline_seconds = ev.Render(base, 0, {alt0}, &base_sky, &rep.evaluator);

  // Worst over the sun angles of test vs ref skies (ref_sun_index: which reference each test
  // sky is compared with; -1 = the same index).
  auto worst_of = [&](const std::vector<Sky>& test, const std::vector<Sky>& ref, BudgetItem* item) {
    double crit = -1.0;
    for (size_t s = 0; s < ref.size(); ++s) {
      if (test[s].empty()) continue;
      SkyCompareInput in{&D, o.sun_zenith_deg[s] * kDeg, 1.0, &ref[s], nullptr, &test[s], &to2020, &toref};
      const SkyError e = CompareSkies(in);
      SkyError& w = item->worst;
      w.rms = std::max(w.rms, e.rms);
      w.rms_corrected = std::max(w.rms_corrected, e.rms_corrected);
      w.max = std::max(w.max, e.max);
      w.color_rms = std::max(w.color_rms, e.color_rms);
      w.duv_rms = std::max(w.duv_rms, e.duv_rms);
      w.directions = std::max(w.directions, e.directions);
      const double c = o.criterion == "rms" ? e.rms : e.max;
      item->by_sun.emplace_back(o.sun_zenith_deg[s], c);
      if (c > crit) {
        crit = c;
        item->worst_sun_zenith_deg = o.sun_zenith_deg[s];
      }
    }
    item->within = (o.criterion == "rms" ? item->worst.rms : item->worst.max) <= o.tolerance;
  };

  // Simplifications of the model.
  struct Simplification {
    std::string name, setting;
    SceneOptions options;
    int orders = 0;
  };
  std::vector<Simplification> simps;
  auto add = [&](std::string name, std::string setting, auto edit) {
    Simplification s{std::move(name), std::move(setting), so};
    edit(s);
    simps.push_back(std::move(s));
  };
  if (base.grid.is_spectral()) {
    add("rgb", "680/550/440 nm, Bruneton's colour rule", [](Simplification& s) { s.options.wavelengths = "rgb"; });
    for (double step : {10.0, 20.0}) {
      if (base.grid.step_nm() > 0.0 && step > base.grid.step_nm()) {
        const double lo_nm = base.grid.wavelength_nm().front();
        const double hi_nm = lo_nm + step * std::floor((base.grid.wavelength_nm().back() - lo_nm) / step);
        add(fmt::format("wavelengths-{:g}nm", step), fmt::format("{:g}-{:g} nm every {:g} nm", lo_nm, hi_nm, step),
            [&](Simplification& s) { s.options.wavelengths = fmt::format("{:g}:{:g}:{:g}", lo_nm, hi_nm, step); });
      }
    }
  }
  const bool any_mie_layer = std::any_of(base.spec.aerosols.begin(), base.spec.aerosols.end(),
                                         [](const AerosolLayerSpec& a) { return !a.optics; });
  if (any_mie_layer) {
    for (const char* p : {"hg", "hg-moment", "cornette-shanks", "dual-lobe"}) {
      if (so.aerosol_phase == p) continue;
      add(std::string("phase-") + p, std::string("aerosol phase ") + p + " (the Mie table's per-wavelength fit)",
          [&](Simplification& s) { s.options.aerosol_phase = p; });
    }
  }
  if (!so.profiles_exponential) {
    add("profiles-exponential", "exponential air and aerosol, tent ozone, measured columns",
        [](Simplification& s) { s.options.profiles_exponential = true; });
  }
  if (!so.no_ozone && (base.profiles.has_ozone || !base.spec.absorbers.empty())) add("no-ozone", "ozone and absorbing layers dropped", [](Simplification& s) { s.options.no_ozone = true; });
  for (int n : {1, 2, 3, 4}) {
    add(fmt::format("orders-{}", n), fmt::format("scattering orders 1-{} ({})", n, o.method), [&](Simplification& s) { s.orders = n; });
  }

  const size_t total = simps.size() + 3;
  size_t done = 0;
  for (const Simplification& s : simps) {
    ReportProgress(progress, "budget: " + s.name, static_cast<double>(done++) / total);
    BudgetItem item;
    item.kind = "simplification";
    item.name = s.name;
    item.setting = s.setting;
    std::vector<std::vector<Sky>> sky;
    if (s.orders > 0) {
      item.wavelengths = base.grid.size();
      item.seconds = ev.Render(base, s.orders, {alt0}, &sky);
    } else {
      const Scene sc = LoadScene(s.options, {});
      item.wavelengths = sc.grid.size();
      item.seconds = ev.Render(sc, 0, {alt0}, &sky);
    }
    worst_of(sky[0], base_sky[0], &item);
    rep.items.push_back(item);
  }

  // LUT dimensions.
  {
    ReportProgress(progress, "budget: altitude", static_cast<double>(done++) / total);
    BudgetItem item;
    item.kind = "lut-dimension";
    item.name = "altitude";
    item.setting = fmt::format("{:g}-{:g} m from the sky at {:g} m", lo, hi, 0.5 * (lo + hi));
    item.wavelengths = base.grid.size();
    std::vector<std::vector<Sky>> sky;
    item.seconds = ev.Render(base, 0, {0.5 * (lo + hi), lo, hi}, &sky);
    BudgetItem a = item, b = item;
    worst_of(sky[0], sky[1], &a);
    worst_of(sky[0], sky[2], &b);
    item = (o.criterion == "rms" ? a.worst.rms >= b.worst.rms : a.worst.max >= b.worst.max) ? a : b;
    for (size_t s = 0; s < item.by_sun.size(); ++s) item.by_sun[s].second = std::max(a.by_sun[s].second, b.by_sun[s].second);
    item.worst.color_rms = std::max(a.worst.color_rms, b.worst.color_rms);
    item.worst.duv_rms = std::max(a.worst.duv_rms, b.worst.duv_rms);
    rep.items.push_back(item);
  }
  {
    ReportProgress(progress, "budget: azimuth", static_cast<double>(done++) / total);
    BudgetItem item;
    item.kind = "lut-dimension";
    item.name = "azimuth";
    item.setting = "the azimuthal mean of each zenith row";
    item.wavelengths = base.grid.size();
    std::vector<Sky> mean = base_sky[0];
    for (size_t s = 0; s < mean.size(); ++s) {
      for (size_t d = 0; d < D.dirs.size(); ++d) {
        std::array<double, 3> acc{0, 0, 0};
        double w = 0.0;
        for (size_t e = 0; e < D.dirs.size(); ++e) {
          if (D.theta_deg[e] != D.theta_deg[d]) continue;
          for (size_t c = 0; c < 3; ++c) acc[c] += D.solid_angle_sr[e] * base_sky[0][s][e][c];
          w += D.solid_angle_sr[e];
        }
        for (size_t c = 0; c < 3; ++c) mean[s][d][c] = acc[c] / w;
      }
    }
    worst_of(mean, base_sky[0], &item);
    rep.items.push_back(item);
  }
  if (o.sun_zenith_deg.size() >= 2) {
    ReportProgress(progress, "budget: sun zenith", static_cast<double>(done++) / total);
    BudgetItem item;
    item.kind = "lut-dimension";
    item.name = "sun-zenith";
    const size_t m = o.sun_zenith_deg.size() / 2;
    item.setting = fmt::format("the sky at {:g} deg for every listed sun angle", o.sun_zenith_deg[m]);
    item.wavelengths = base.grid.size();
    std::vector<Sky> fixed(base_sky[0].size(), base_sky[0][m]);
    fixed[m].clear();  // the slice itself is not compared
    worst_of(fixed, base_sky[0], &item);
    rep.items.push_back(item);
  }
  ReportProgress(progress, "budget", 1.0);
  return rep;
}

std::string BudgetCsv(const BudgetReport& r) {
  std::string out = fmt::format(
      "# source: sky-render budget; evaluator: {}; tolerance {} ({} of the relative luminance error over the sky outside a 1 deg "
      "aureole, worst over the sun angles); baseline {} wavelengths\n",
      [&] {
        std::string e = r.evaluator;
        std::replace(e.begin(), e.end(), '\n', ' ');
        return e;
      }(),
      r.tolerance, r.criterion, r.baseline_wavelengths);
  out += "kind,name,setting,wavelengths,rms_rel,max_rel,color_rms_rec2020,duv_rms,worst_sun_zenith_deg,within_tolerance,"
         "error_by_sun_zenith\n";
  for (const BudgetItem& i : r.items) {
    std::string by;
    for (const auto& [z, e] : i.by_sun) by += fmt::format("{}{:g}:{:.5f}", by.empty() ? "" : " ", z, e);
    out += fmt::format("{},{},\"{}\",{},{:.5f},{:.5f},{:.5f},{:.5f},{:g},{},{}\n", i.kind, i.name, i.setting, i.wavelengths,
                       i.worst.rms, i.worst.max, i.worst.color_rms, i.worst.duv_rms, i.worst_sun_zenith_deg, i.within ? "yes" : "no",
                       by);
  }
  return out;
}

std::string BudgetTable(const BudgetReport& r) {
  std::string out = fmt::format("tolerance {:.3g} % ({}); baseline: {} wavelengths, {:.2f} s\n", 100 * r.tolerance, r.criterion,
                                r.baseline_wavelengths, r.baseline_seconds);
  out += fmt::format("{:<15} {:<22} {:>4} {:>9} {:>9} {:>9} {:>7} {:>8} {:>7}  {:<6}  {}\n", "kind", "name", "wl", "rms %", "max %",
                     "colour %", "du'v'", "seconds", "speedup", "within", "error by sun zenith (deg: %)");
  for (const BudgetItem& i : r.items) {
    std::string by;
    for (const auto& [z, e] : i.by_sun) by += fmt::format("{}{:g}: {:.3g}", by.empty() ? "" : ", ", z, 100 * e);
    const std::string secs = i.seconds > 0 ? fmt::format("{:.2f}", i.seconds) : "-";
    const std::string speed = i.seconds > 0 ? fmt::format("{:.2f}", r.baseline_seconds / i.seconds) : "-";
    out += fmt::format("{:<15} {:<22} {:>4} {:>9.3f} {:>9.3f} {:>9.3f} {:>7.4f} {:>8} {:>7}  {:<6}  {}\n", i.kind, i.name, i.wavelengths,
                       100 * i.worst.rms, 100 * i.worst.max, 100 * i.worst.color_rms, i.worst.duv_rms, secs, speed,
                       i.within ? "yes" : "no", by);
  }
  return out;
}

}  // namespace skybake
