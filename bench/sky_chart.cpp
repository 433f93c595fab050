// bench_sky_chart: the speed-vs-accuracy chart of the sky methods (docs/sky-methods.md
// "The chart"). For a fixed scene set - the clear and hazed atmospheres, sun elevations 60, 20,
// 5, 0, -4 and -10 deg, the 91 sky directions of transport/sky_error.h - it renders
//   - a converged path-traced reference per scene, cached under <out>/references/ in a CSV named
//     by a hash of everything it depends on (the resolved scene, the content of every input file,
//     the directions, the tracer settings and the tracer's source), so a re-run only renders
//     what changed;
//   - every registered deterministic method (SkyMethodNames(): whatever is registered, e.g.
//     `single`, `orders`) at every quality (low, medium, high), timed on one thread (table
//     building + the 91 directions);
//   - the path tracer itself at 10 % and 3 % target error (cached like the references; time =
//     wall x threads, the tracer scales linearly; `--methods` without `path` leaves it out);
//   - the model simplifications (RGB, a 20 nm grid, HG / Cornette-Shanks / dual-lobe phases,
//     exponential profiles, no ozone, capped orders) with ms-approx at medium quality,
// and writes <out>/chart.csv (one row per scene x method x quality x variant), <out>/sky_errors.csv
// (the per-direction relative error, for the heat maps) and <out>/references.csv. The figures are
// printed as they come; scripts/chart plots them.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "color/color.h"
#include "io/cli.h"
#include "io/csv.h"
#include "io/fileio.h"
#include "transport/method_ms_approx.h"
#include "transport/path_tracer.h"
#include "transport/sky_error.h"
#include "transport/sky_method.h"
#include "transport/sky_scene.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {

constexpr double kPi = 3.14159265358979323846;
using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The reference's path-tracer settings per sun elevation: 0.5 % standard error of Y in daylight,
// 1 % near the horizon, 2 % at -4 deg and 5 % at -10 deg, where rare multiple-scattering paths
// through the sunlit upper atmosphere dominate (more paths at least, docs/sky-render.md).
// `daylight_error` > 0 replaces the targets from 0 deg up (the cloudy skies' references: 1 %,
// docs/sky-render.md "Clouds").
PathTracerSettings ReferenceSettings(double elevation_deg, double daylight_error = 0.0) {
  PathTracerSettings s;
  s.min_paths = 256;
  if (elevation_deg >= 0 && daylight_error > 0) {
    s.target_relative_error = daylight_error;
  } else if (elevation_deg >= 10) {
    s.target_relative_error = 0.005;
  } else if (elevation_deg >= 0) {
    s.target_relative_error = 0.01;
  } else if (elevation_deg >= -5) {
    s.target_relative_error = 0.02;
    s.min_paths = 4096;
  } else {
    s.target_relative_error = 0.05;
    s.min_paths = 16384;
  }
  return s;
}

std::string SettingsText(const PathTracerSettings& s) {
  return fmt::format("target {} min_paths {} max_paths {} wavelengths_per_path {} seed {} rr {} segment_nee {} max_order {}",
                     s.target_relative_error, s.min_paths, s.max_paths, s.wavelengths_per_path, s.seed,
                     s.russian_roulette_depth, s.segment_nee, s.max_order);
}

struct PathResult {
  std::vector<std::array<double, 3>> xyz;
  std::vector<double> y_stderr;
  uint64_t paths = 0;
  double cpu_s = 0.0;  // wall x threads when rendered
  bool cached = false;
};

// Renders (or reads from the cache) the path-traced sky for the directions.
PathResult PathSky(const Scene& scene, const SkyDirections& D, double sun_zenith_rad, const PathTracerSettings& ps,
                   const fs::path& cache_dir, const std::string& label, const std::string& key_text) {
  const std::string key = HashBytes(key_text + SettingsText(ps));
  const fs::path file = cache_dir / fmt::format("{}_{}.csv", label, key.substr(0, 16));
  PathResult r;
  if (fs::exists(file)) {
    CsvTable csv = CsvTable::Load(file);
    Diagnostics d;
    std::vector<double> x = csv.Numbers("X", d), y = csv.Numbers("Y", d), z = csv.Numbers("Z", d),
                        se = csv.Numbers("Y_stderr", d), paths = csv.Numbers("paths", d), cpu = csv.Numbers("cpu_s", d);
    d.ThrowIfAny();
    if (csv.rows() == D.dirs.size()) {
      for (size_t i = 0; i < csv.rows(); ++i) {
        r.xyz.push_back({x[i], y[i], z[i]});
        r.y_stderr.push_back(se[i]);
        r.paths += static_cast<uint64_t>(paths[i]);
      }
      r.cpu_s = cpu.front();
      r.cached = true;
      return r;
    }
  }
  PathTracer tracer(scene.model, scene.xyz_weights, ps);
  const glm::dvec3 x(0, 0, scene.model.bottom_radius_m + scene.spec.observer_altitude_m);
  const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
  std::vector<ColorEstimate> est(D.dirs.size());
  const auto t0 = Clock::now();
  tbb::parallel_for(size_t{0}, D.dirs.size(), size_t{1}, [&](size_t d) {
    est[d] = tracer.Radiance(x, glm::dvec3(D.dirs[d][0], D.dirs[d][1], D.dirs[d][2]), sun, d);
  });
  r.cpu_s = Seconds(t0) * tbb::this_task_arena::max_concurrency();
  std::string out = fmt::format("# source: bench_sky_chart, path tracer ({}), {}; observer XYZ in cd/m^2\n", SettingsText(ps), label);
  out += "theta_deg,phi_deg,X,Y,Z,Y_stderr,paths,cpu_s\n";
  for (size_t d = 0; d < D.dirs.size(); ++d) {
    r.xyz.push_back(est[d].xyz);
    r.y_stderr.push_back(est[d].xyz_stderr[1]);
    r.paths += est[d].paths;
    out += fmt::format("{},{},{:.9e},{:.9e},{:.9e},{:.6e},{},{:.3f}\n", D.theta_deg[d], D.phi_deg[d], est[d].xyz[0], est[d].xyz[1],
                       est[d].xyz[2], est[d].xyz_stderr[1], est[d].paths, r.cpu_s);
  }
  fs::create_directories(cache_dir);
  WriteFileIfChanged(file, out);
  // A reference is a cache entry: it is kept as soon as it is rendered, so that a chart stopped
  // later (references of cloudy or deep-twilight skies take hours) does not lose it.
  CommitOutputTransaction();
  return r;
}

struct Variant {
  std::string name;      // "" = the full model
  SceneOptions options;  // the scene with this simplification
  int orders = 0;        // capped orders (ms-approx)
};

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("bench_sky_chart", "The speed-vs-accuracy chart of the sky methods (docs/sky-methods.md, 'The chart').");
  std::string out_dir = "outputs/chart", mie_dir = "outputs/mie";
  std::vector<std::string> atmospheres = {"clear", "hazed"};
  std::vector<double> elevations = {60, 20, 5, 0, -4, -10};
  bool no_variants = false, references_only = false;
  double reference_error = 0.0;
  std::vector<std::string> methods;
  std::vector<std::string> qualities = QualityNames();
  cli.app().add_option("--out", out_dir, "Output folder (CSV; references cached in <out>/references)");
  cli.app().add_option("--mie-dir", mie_dir, "Folder with the Mie tables of the atmospheres' particle types");
  cli.app().add_option("--atmospheres", atmospheres, "Atmospheres (atmospheres/<name>.yaml)")->delimiter(',');
  cli.app().add_option("--elevations", elevations, "Sun elevations (deg)")->delimiter(',');
  cli.app().add_flag("--no-variants", no_variants, "Skip the model simplifications");
  cli.app().add_flag("--references-only", references_only, "Only render (or check) the cached references");
  cli.app()
      .add_option("--reference-error", reference_error,
                  "Target relative standard error of the references from sun elevation 0 up (default: 0.5 % from 10 deg, "
                  "1 % at 0-10 deg)")
      ->check(CLI::Range(0.001, 0.5));
  cli.app()
      .add_option("--methods", methods,
                  "Methods: registered deterministic ones and `path` (the path tracer at 10 % and 3 %); default: all")
      ->delimiter(',');
  cli.app()
      .add_option("--qualities", qualities, "Qualities of the deterministic methods (default: low,medium,high)")
      ->delimiter(',')
      ->check(CLI::IsMember(QualityNames()));
  return cli.Run(argc, argv, [&] {
    const fs::path root = SKYBAKE_SOURCE_DIR;
    const SkyDirections D = ChartDirections();
    std::string dirs_text;
    for (size_t d = 0; d < D.dirs.size(); ++d) dirs_text += fmt::format("{} {};", D.theta_deg[d], D.phi_deg[d]);
    const std::string tracer_source = HashFile(root / "tools/core/transport/path_tracer.cpp") +
                                      HashFile(root / "tools/core/transport/path_tracer.h");
    std::string chart = "# source: bench_sky_chart (docs/sky-methods.md, 'The chart'); errors outside a 1 deg aureole over the 91 sky "
                        "directions of transport/sky_error.h; time_s = build_s + render_s on one thread (path: wall x threads)\n";
    chart += "atmosphere,sun_elevation_deg,method,quality,variant,time_s,build_s,render_s,rms_rel,rms_rel_corrected,max_rel,"
             "color_rms_rec2020,duv_rms,ref_noise_rms,ref_noise_max,directions\n";
    std::string sky = "# source: bench_sky_chart; rel_err = Y/Y_ref - 1 (empty inside the 1 deg aureole)\n"
                      "atmosphere,sun_elevation_deg,method,quality,variant,theta_deg,phi_deg,rel_err,ref_rel_stderr\n";
    std::string refs = "# source: bench_sky_chart references (path tracer, cached)\n"
                       "atmosphere,sun_elevation_deg,target_error,paths,cpu_s,noise_rms,noise_max,cached\n";
    // The methods of every scene: the registered ones by default, and the path tracer's rows
    // unless --methods names methods without `path`.
    const bool path_rows = methods.empty() || std::find(methods.begin(), methods.end(), "path") != methods.end();
    if (methods.empty()) methods = SkyMethodNames();

    for (const std::string& atm : atmospheres) {
      SceneOptions base;
      base.atmosphere = (root / "atmospheres" / (atm + ".yaml")).string();
      base.mie_dir = mie_dir;
      const Scene scene = LoadScene(base, {});
      std::string key_text = scene.parameters + dirs_text + tracer_source;
      for (const fs::path& f : scene.files_read) key_text += HashFile(f);
      const ColorConfig config = ColorConfig::Load(scene.ocio_config);
      const ColorProcessor to2020 = config.Converter(XyzColorSpace(scene.observer), ocio_names::kLinearRec2020);
      const ColorProcessor toref = config.Converter(XyzColorSpace(scene.observer), ocio_names::kCieXyzD65);

      // References first (the expensive part), so the methods compare against them.
      std::vector<PathResult> ref;
      for (double elev : elevations) {
        const PathTracerSettings ps = ReferenceSettings(elev, reference_error);
        const auto t0 = Clock::now();
        ref.push_back(PathSky(scene, D, (90.0 - elev) * kPi / 180.0, ps, fs::path(out_dir) / "references",
                              fmt::format("{}_elev{:+03.0f}", atm, elev), key_text));
        const PathResult& r = ref.back();
        SkyError self;
        {
          SkyCompareInput in{&D, (90.0 - elev) * kPi / 180.0, 1.0, &r.xyz, &r.y_stderr, &r.xyz, &to2020, &toref};
          self = CompareSkies(in);
        }
        std::printf("reference %s %+.0f deg: target %.3f, %llu paths, %.0f cpu-s%s, noise RMS %.4f max %.4f (%.0f s)\n",
                    atm.c_str(), elev, ps.target_relative_error, static_cast<unsigned long long>(r.paths), r.cpu_s,
                    r.cached ? " (cached)" : "", self.ref_noise_rms, self.ref_noise_max, Seconds(t0));
        std::fflush(stdout);
        refs += fmt::format("{},{},{},{},{:.1f},{:.5f},{:.5f},{}\n", atm, elev, ps.target_relative_error, r.paths, r.cpu_s,
                            self.ref_noise_rms, self.ref_noise_max, r.cached ? 1 : 0);
      }

      if (references_only) continue;
      auto record = [&](double elev, size_t e, const std::string& method, const std::string& quality, const std::string& variant,
                        double build_s, double render_s, const std::vector<std::array<double, 3>>& xyz) {
        std::vector<double> per;
        SkyCompareInput in{&D, (90.0 - elev) * kPi / 180.0, 1.0, &ref[e].xyz, &ref[e].y_stderr, &xyz, &to2020, &toref};
        const SkyError err = CompareSkies(in, &per);
        chart += fmt::format("{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{}\n", atm, elev,
                             method, quality, variant, build_s + render_s, build_s, render_s, err.rms, err.rms_corrected,
                             err.max, err.color_rms, err.duv_rms, err.ref_noise_rms, err.ref_noise_max, err.directions);
        for (size_t d = 0; d < D.dirs.size(); ++d) {
          sky += fmt::format("{},{},{},{},{},{},{},{},{:.5f}\n", atm, elev, method, quality, variant, D.theta_deg[d], D.phi_deg[d],
                             std::isnan(per[d]) ? std::string() : fmt::format("{:.6f}", per[d]),
                             ref[e].y_stderr[d] / ref[e].xyz[d][1]);
        }
        std::printf("  %s %+4.0f %-9s %-6s %-16s %8.3f s  RMS %.4f (corr %.4f)  max %.3f  colour %.4f  du'v' %.4f\n", atm.c_str(), elev,
                    method.c_str(), quality.c_str(), variant.empty() ? "-" : variant.c_str(), build_s + render_s, err.rms,
                    err.rms_corrected, err.max, err.color_rms, err.duv_rms);
        std::fflush(stdout);
      };

      // Every registered deterministic method x quality, on one thread.
      auto run_method = [&](const Scene& sc, const std::string& name, const SkyMethodOptions& mo, const std::string& variant) {
        tbb::task_arena one(1);
        one.execute([&] {
          const auto t0 = Clock::now();
          const SkyMethodOptions& o = mo;
          std::unique_ptr<SkyMethod> method = MakeSkyMethod(name, sc.model, o, {});
          const double build_s = Seconds(t0);
          for (size_t e = 0; e < elevations.size(); ++e) {
            const auto t1 = Clock::now();
            std::vector<double> L;
            method->Radiance(sc.spec.observer_altitude_m, (90.0 - elevations[e]) * kPi / 180.0, D.dirs, &L);
            const double render_s = Seconds(t1);
            record(elevations[e], e, name, QualityName(o.quality), variant, build_s, render_s, SpectralToXyz(L, sc.xyz_weights));
          }
        });
      };
      for (const std::string& name : methods) {
        if (name == "path") continue;
        for (const std::string& q : qualities) {
          SkyMethodOptions o;
          o.quality = ParseQuality(q, "--qualities");
          run_method(scene, name, o, "");
        }
      }
      // The path tracer at 10 % and 3 %.
      for (const auto& [quality, target] : std::vector<std::pair<std::string, double>>{{"low", 0.1}, {"medium", 0.03}}) {
        if (!path_rows) break;
        for (size_t e = 0; e < elevations.size(); ++e) {
          PathTracerSettings ps;
          ps.target_relative_error = target;
          ps.seed = 7;  // independent of the reference's streams
          if (target <= ReferenceSettings(elevations[e], reference_error).target_relative_error) continue;
          const PathResult r = PathSky(scene, D, (90.0 - elevations[e]) * kPi / 180.0, ps, fs::path(out_dir) / "references",
                                       fmt::format("{}_elev{:+03.0f}_path{}", atm, elevations[e], quality), key_text);
          record(elevations[e], e, "path", quality, "", 0.0, r.cpu_s, r.xyz);
        }
      }
      if (no_variants) continue;
      // The model simplifications, with ms-approx at medium quality.
      std::vector<Variant> variants;
      auto with = [&](const std::string& name, auto edit) {
        Variant v{name, base};
        edit(v);
        variants.push_back(v);
      };
      with("rgb", [](Variant& v) { v.options.wavelengths = "rgb"; });
      with("wavelengths-20nm", [](Variant& v) { v.options.wavelengths = "360:820:20"; });
      with("phase-hg", [](Variant& v) { v.options.aerosol_phase = "hg"; });
      with("phase-cornette-shanks", [](Variant& v) { v.options.aerosol_phase = "cornette-shanks"; });
      with("phase-dual-lobe", [](Variant& v) { v.options.aerosol_phase = "dual-lobe"; });
      with("profiles-exponential", [](Variant& v) { v.options.profiles_exponential = true; });
      with("no-ozone", [](Variant& v) { v.options.no_ozone = true; });
      with("orders-2", [](Variant& v) { v.orders = 2; });
      with("orders-4", [](Variant& v) { v.orders = 4; });
      for (const Variant& v : variants) {
        const Scene sc = v.options.wavelengths == base.wavelengths && v.options.aerosol_phase == base.aerosol_phase &&
                                 !v.options.profiles_exponential && !v.options.no_ozone
                             ? Scene{}
                             : LoadScene(v.options, {});
        const Scene& use = sc.xyz_weights.empty() ? scene : sc;
        SkyMethodOptions o;
        o.quality = Quality::kMedium;
        o.orders = v.orders;
        run_method(use, "ms-approx", o, v.name);
      }
    }
    fs::create_directories(out_dir);
    if (references_only) {
      WriteFileIfChanged(fs::path(out_dir) / "references.csv", refs);
      return;
    }
    WriteFileIfChanged(fs::path(out_dir) / "chart.csv", chart);
    WriteFileIfChanged(fs::path(out_dir) / "sky_errors.csv", sky);
    WriteFileIfChanged(fs::path(out_dir) / "references.csv", refs);
    std::printf("wrote %s/chart.csv, sky_errors.csv, references.csv\n", out_dir.c_str());
  });
}
