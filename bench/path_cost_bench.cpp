// The path tracer's cost per view direction (docs/sky-render.md "Deep twilight" and "Clouds"):
// per direction the relative standard deviation of Y per path, the share of the largest path and
// of the ten largest, the paths and the CPU seconds (one thread) that a 1 % standard error needs,
// with the default estimator or with its guides switched off.
//
//   build/test/bin/bench_path_cost [--atmosphere clear] [--sun-zenith-deg 98] [--paths 200000]
//                                  [--plain-twilight] [--plain-clouds] [--plain]
//
// --plain-twilight: without the twilight estimators (sun_guided_nee, twilight_guide);
// --plain-clouds: without the cloud estimators (sun_peak_guide, split_above, nee_roulette);
// --plain: both. The cloud estimators act only where a component's phase function peaks above
// sun_peak_min (the cloudy skies). The paths run as the adaptive estimator runs them (ColorPath
// with the NEE roulette's floor at nee_roulette x the running mean of Y, updated every 64 paths).
//
// The scene is the tests' (tests/transport/method_scenes.h: the atmosphere's Mie tables built in
// process on a 20 nm grid, 380-780 nm), so that the figures need no baked outputs/.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "io/cli.h"
#include "transport/method_scenes.h"

using namespace skybake;
using namespace skybake::testing;

int main(int argc, char** argv) {
  ToolCli cli("bench_path_cost", "The path tracer's cost per view direction (docs/sky-render.md 'Deep twilight', 'Clouds').");
  std::string atmosphere = "clear";
  double sun_zenith = 98.0;
  uint64_t paths = 200000;
  bool plain = false, plain_twilight = false, plain_clouds = false;
  cli.app().add_option("--atmosphere", atmosphere, "Atmosphere (atmospheres/<name>.yaml)");
  cli.app().add_option("--sun-zenith-deg", sun_zenith, "Sun zenith angle (deg; 98 = 8 deg below the horizon)")->check(CLI::Range(0.0, 120.0));
  cli.app().add_option("--paths", paths, "Fixed-count paths per direction")->check(CLI::Range(uint64_t{100}, uint64_t{1} << 30));
  cli.app().add_flag("--plain-twilight", plain_twilight, "Without the twilight estimators (sun_guided_nee, twilight_guide off)");
  cli.app().add_flag("--plain-clouds", plain_clouds, "Without the cloud estimators (sun_peak_guide, split_above, nee_roulette off)");
  cli.app().add_flag("--plain", plain, "Without either");
  return cli.Run(argc, argv, [&] {
    const TestScene sc = LoadTestScene(atmosphere);
    PathTracerSettings ps;
    if (plain || plain_twilight) {
      ps.sun_guided_nee = false;
      ps.twilight_guide = false;
    }
    if (plain || plain_clouds) {
      ps.sun_peak_guide = 0.0;
      ps.split_above = 0.0;
      ps.nee_roulette = 0.0;
    }
    const PathTracer pt(sc.model, sc.weights, ps);
    const glm::dvec3 pos(0, 0, sc.model.bottom_radius_m + 1.0), sun = DirectionFromAngles(sun_zenith * kDeg, 0.0);
    struct View {
      const char* name;
      double zenith_deg, azimuth_deg;  // azimuth from the sun's
    };
    const View views[] = {{"zenith", 0, 0}, {"sun 45", 45, 0}, {"sun 80", 80, 0}, {"sun 88", 88, 0}, {"anti 60", 60, 180}, {"side 85", 85, 90}};
    std::printf("%s, sun zenith %.1f deg, %llu paths per direction%s%s\n", atmosphere.c_str(), sun_zenith,
                static_cast<unsigned long long>(paths), plain || plain_twilight ? ", plain twilight" : "",
                plain || plain_clouds ? ", plain clouds" : "");
    std::printf("cloud estimators %s, minimum paths of an adaptive estimate %llu\n", pt.CloudEstimators() ? "on" : "off",
                static_cast<unsigned long long>(pt.MinPaths()));
    std::printf("%-8s %12s %12s %10s %10s %12s %10s\n", "view", "Y cd/m2", "sigma/Y/path", "max share", "top-10", "paths 1%", "CPU s 1%");
    double total_s = 0.0;
    for (const View& v : views) {
      const glm::dvec3 d = DirectionFromAngles(v.zenith_deg * kDeg, v.azimuth_deg * kDeg);
      const auto t0 = std::chrono::steady_clock::now();
      std::vector<double> y(paths);
      double floor_y = 0.0, running = 0.0;
      for (uint64_t n = 0; n < paths; ++n) {
        double xyz[3];
        pt.ColorPath(pos, d, sun, 7, n, xyz, floor_y);
        y[n] = xyz[1];
        running += xyz[1];
        if ((n + 1) % 64 == 0 && pt.CloudEstimators()) floor_y = ps.nee_roulette * std::abs(running) / static_cast<double>(n + 1);
      }
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      double sum = 0, sum2 = 0;
      for (double x : y) {
        sum += x;
        sum2 += x * x;
      }
      const double mean = sum / paths, cv = std::sqrt(std::max(0.0, sum2 / paths - mean * mean)) / mean;
      std::sort(y.begin(), y.end());
      double top10 = 0.0;
      for (uint64_t i = paths - 10; i < paths; ++i) top10 += y[i];
      const double need = cv * cv * 1e4, need_s = need * s / paths;
      total_s += need_s;
      std::printf("%-8s %12.5g %12.2f %10.3f %10.3f %12.3g %10.0f\n", v.name, mean, cv, y.back() / sum, top10 / sum, need, need_s);
    }
    std::printf("CPU seconds for 1 %% in all six directions: %.0f\n", total_s);
  });
}
