// bench_orders_nodes: the error of `orders` table settings, measured against the same method with
// those settings converged (no noise) and against the cached path reference of the tests
// (tests/transport/references/, noise-corrected RMS), on the tests' scene of an atmosphere
// (tests/transport/method_scenes.h, 20 nm grid) and their ten directions (SkyAngles), `high` plus
// expert overrides. docs/sky-methods.md "Radius nodes under a cloud" has its figures:
//
//   build/test/bin/bench_orders_nodes --atmosphere cloudy4 --converged radius_dtau_x100=8,radius_max=140
//       --candidates radius_dtau_x100=15 radius_dtau_x100=25 radius_dtau_x100=0,radius=64    (one command line)
//
// Per candidate: its radius nodes, its build's wall time, RMS and max |error| against the
// converged settings and against the path (the reference file <atmosphere>_sun<Z>.csv, if it is
// of this scene); with --per-direction also its truncation cones and each direction's signed error
// ("Truncation cone per component" has those figures). With --grid, 77 directions (the horizon band and the ground just below it
// among them) and no path; "The twilight split" has those figures:
//
//   build/test/bin/bench_orders_nodes --atmosphere clear --sun-zenith-deg 91,95,98,105 --grid
//       --converged split_from_deg=0 --candidates "" split_azimuth=8    (one command line)
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/cli.h"
#include "io/error.h"
#include "transport/method_scenes.h"
#include "transport/sky_method.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

// "key=value,key=value" into SkyMethodOptions::table_size.
std::map<std::string, int> ParseOverrides(const std::string& text) {
  std::map<std::string, int> out;
  size_t p = 0;
  while (p < text.size()) {
    size_t e = text.find(',', p);
    if (e == std::string::npos) e = text.size();
    const std::string kv = text.substr(p, e - p);
    const size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("an override is key=value: '" + kv + "'");
    try {
      out[kv.substr(0, eq)] = std::stoi(kv.substr(eq + 1));
    } catch (const std::exception&) {
      throw UsageError("an override's value is an integer: '" + kv + "'");
    }
    p = e + 1;
  }
  return out;
}

struct Solve {
  std::vector<std::vector<double>> y;  // per sun zenith, per direction
  double seconds = 0.0;
  std::string nodes;
  std::string cones;
};

// The tests' ten directions (SkyAngles), or with grid 77: view zenith 0-89.5 deg and 92 deg (the
// ground just below the horizon) x azimuth 0-180 deg every 30 deg from the sun's.
std::vector<std::array<double, 3>> Directions(bool grid) {
  if (!grid) return SkyDirs();
  std::vector<std::array<double, 3>> dirs;
  for (double vz : {0.0, 15.0, 30.0, 45.0, 60.0, 70.0, 80.0, 85.0, 88.0, 89.5, 92.0}) {
    for (double az = 0.0; az <= 180.0; az += 30.0) dirs.push_back(Dir(vz, az));
  }
  return dirs;
}

Solve Run(const TestScene& sc, const std::string& overrides, const std::vector<double>& sun_zenith_deg,
          const std::vector<std::array<double, 3>>& dirs) {
  SkyMethodOptions o;
  o.quality = Quality::kHigh;
  o.table_size = ParseOverrides(overrides);
  const auto t0 = std::chrono::steady_clock::now();
  const std::unique_ptr<SkyMethod> m = MakeSkyMethod("orders", sc.model, o, {});
  Solve s;
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (double sz : sun_zenith_deg) s.y.push_back(MethodY(sc, *m, sz, dirs));
  const std::string desc = m->Describe();
  const size_t at = desc.find("radius_nodes: ");
  s.nodes = at == std::string::npos ? "?" : desc.substr(at + 14, desc.find('\n', at) - at - 14);
  const size_t tr = desc.find("truncation_deg: ");
  if (tr != std::string::npos) s.cones = desc.substr(tr, desc.find('\n', tr) - tr);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("bench_orders_nodes", "The error of orders table settings against converged settings and the cached path reference.");
  std::string atmosphere = "cloudy4", converged;
  std::vector<double> sun_zeniths = {30.0};
  std::vector<std::string> candidates;
  bool grid = false, per_direction = false;
  cli.app().add_option("--atmosphere", atmosphere, "Atmosphere (atmospheres/<name>.yaml)");
  cli.app()
      .add_option("--sun-zenith-deg", sun_zeniths, "Sun zenith angles (deg, comma-separated; the path comparison needs one)")
      ->check(CLI::Range(0.0, 120.0))
      ->delimiter(',');
  cli.app().add_option("--converged", converged, "Overrides of the converged solve (key=value,...); empty: none")->required();
  cli.app().add_option("--candidates", candidates, "Overrides of each candidate (key=value,...; \"\" is high itself)")->required();
  cli.app().add_flag("--grid", grid, "77 directions (11 view zeniths x 7 azimuths) instead of the tests' ten; no path comparison");
  cli.app().add_flag("--per-direction", per_direction, "Also print each direction's signed error against the path (or the converged solve)");
  return cli.Run(argc, argv, [&] {
    const TestScene sc = LoadTestScene(atmosphere);
    const std::vector<std::array<double, 3>> dirs = Directions(grid);
    CachedReference ref;
    if (!grid && sun_zeniths.size() == 1) {
      const std::string ref_name = fmt::format("{}_sun{:g}.csv", atmosphere, sun_zeniths[0]);
      if (std::filesystem::exists(CachedReferencePath(ref_name))) {
        ref = ReadCachedReference(ref_name, sc);
        if (!ref.same_scene) std::printf("%s is of another scene: no comparison with the path\n", ref_name.c_str());
      }
    }
    const Solve conv = Run(sc, converged, sun_zeniths, dirs);
    std::printf("%s, %zu directions, converged (%s): %s radius nodes, %.0f s\n", atmosphere.c_str(), dirs.size(), converged.c_str(),
                conv.nodes.c_str(), conv.seconds);
    std::printf("%-40s %6s %6s %8s  %-22s %-22s\n", "candidate", "sun", "nodes", "build s", "vs converged RMS (max)", "vs path RMS (max)");
    for (const std::string& c : candidates) {
      const Solve s = Run(sc, c, sun_zeniths, dirs);
      for (size_t k = 0; k < sun_zeniths.size(); ++k) {
        double ss = 0.0, mx = 0.0, sp = 0.0, noise = 0.0, mp = 0.0;
        for (size_t d = 0; d < dirs.size(); ++d) {
          const double e = s.y[k][d] / conv.y[k][d] - 1.0;
          ss += e * e, mx = std::max(mx, std::abs(e));
          if (ref.same_scene) {
            const double ep = s.y[k][d] / ref.y[d] - 1.0, sd = ref.y_stderr[d] / ref.y[d];
            sp += ep * ep, noise += sd * sd, mp = std::max(mp, std::abs(ep));
          }
        }
        const double n = static_cast<double>(dirs.size());
        const std::string path = ref.same_scene ? fmt::format("{:.2f} % ({:.2f})", 100.0 * std::sqrt(std::max(0.0, sp - noise) / n), 100.0 * mp)
                                                : std::string("-");
        std::printf("%-40s %6g %6s %8.0f  %-22s %-22s\n", c.empty() ? "(high)" : c.c_str(), sun_zeniths[k], s.nodes.c_str(), s.seconds,
                    fmt::format("{:.3f} % ({:.3f})", 100.0 * std::sqrt(ss / n), 100.0 * mx).c_str(), path.c_str());
        if (per_direction) {
          std::printf("  %s\n", s.cones.c_str());
          std::string line = "  per direction (view zenith/azimuth deg: % off the " + std::string(ref.same_scene ? "path" : "converged solve") + "):";
          for (size_t d = 0; d < dirs.size(); ++d) {
            const double base = ref.same_scene ? ref.y[d] : conv.y[k][d];
            const double vz = std::acos(dirs[d][2]) * 180.0 / M_PI, az = std::atan2(dirs[d][1], dirs[d][0]) * 180.0 / M_PI;
            line += fmt::format(" {:g}/{:g} {:+.2f}", std::round(vz * 10.0) / 10.0, std::round(az), 100.0 * (s.y[k][d] / base - 1.0));
          }
          std::printf("%s\n", line.c_str());
        }
      }
    }
  });
}
