// bench_test_references: renders a cached path-traced reference that the sky-method tests compare
// `orders` with (MethodOrders.HighAgainstCachedPathReferences): the tests' scene of an atmosphere
// (tests/transport/method_scenes.h: its Mie tables built in process, 380-780 nm every 20 nm), the
// tests' ten directions (SkyAngles), one sun angle, every direction to a target relative
// standard error of Y. The file holds the scene's fingerprint (SceneFingerprint), so that a test
// can tell a reference of another scene; re-render after a change of the scene or the tracer:
//
//   build/test/bin/bench_test_references --atmosphere cloudy1 --sun-zenith-deg 30 --target-error 0.01
//       -o tests/transport/references/cloudy1_sun30.csv    (one command line)
//
// Directions run in parallel (--threads); each is one estimate with its own stream, so the file's
// numbers do not depend on the thread count. cpu_s is each direction's CPU time on the thread
// that ran it, which other jobs on the machine do not inflate as they would its wall time.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <time.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/cli.h"
#include "io/fileio.h"
#include "transport/method_scenes.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

// The calling thread's CPU time (s): a direction's estimate runs on one thread from start to end.
double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("bench_test_references", "A cached path reference for the sky-method tests (tests/transport/references/).");
  std::string atmosphere = "cloudy1", out;
  double sun_zenith = 30.0, target = 0.01;
  uint64_t max_paths = uint64_t{1} << 20, seed = 1;
  std::vector<size_t> only;
  cli.app().add_option("--atmosphere", atmosphere, "Atmosphere (atmospheres/<name>.yaml)");
  cli.app().add_option("--sun-zenith-deg", sun_zenith, "Sun zenith angle (deg)")->check(CLI::Range(0.0, 120.0));
  cli.app().add_option("--target-error", target, "Relative standard error of Y per direction")->check(CLI::Range(0.001, 0.5));
  cli.app().add_option("--max-paths", max_paths, "Path cap per direction (deep twilight needs more than the default 2^20)")
      ->check(CLI::Range(uint64_t{1024}, uint64_t{1} << 30));
  cli.app().add_option("--seed", seed, "Path tracer seed (another seed: an independent estimate)");
  cli.app().add_option("--directions", only, "Only these directions (indices 0-9 into the tests' ten), a check; the file then holds only them")
      ->check(CLI::Range(size_t{0}, size_t{9}))
      ->delimiter(',');
  cli.app().add_option("-o,--output", out, "Output CSV")->required();
  return cli.Run(argc, argv, [&] {
    const TestScene sc = LoadTestScene(atmosphere);
    PathTracerSettings ps;
    ps.target_relative_error = target;
    ps.min_paths = 1024;
    ps.max_paths = max_paths;
    ps.seed = seed;
    const PathTracer pt(sc.model, sc.weights, ps);
    const glm::dvec3 x(0, 0, sc.model.bottom_radius_m + 1.0), sun = DirectionFromAngles(sun_zenith * kDeg, 0.0);
    const std::vector<std::array<double, 3>>& dirs = SkyDirs();
    if (only.empty()) {
      for (size_t d = 0; d < dirs.size(); ++d) only.push_back(d);
    }
    std::vector<ColorEstimate> est(dirs.size());
    std::vector<double> seconds(dirs.size());
    tbb::parallel_for(size_t{0}, only.size(), size_t{1}, [&](size_t k) {
      const size_t d = only[k];
      const double t0 = ThreadCpuSeconds();
      est[d] = pt.Radiance(x, glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]), sun, 300 + d);
      seconds[d] = ThreadCpuSeconds() - t0;
    });
    std::string text = fmt::format(
        "# source: bench_test_references --atmosphere {} --sun-zenith-deg {} --target-error {}{} (path tracer, seed {}, "
        "streams 300 + direction; the tests' scene, tests/transport/method_scenes.h); Y in cd/m^2, cpu_s on one thread\n",
        atmosphere, sun_zenith, target, max_paths == (uint64_t{1} << 20) ? std::string() : fmt::format(" --max-paths {}", max_paths),
        ps.seed);
    text += "# scene:";
    for (double v : SceneFingerprint(sc)) text += fmt::format(" {:.9e}", v);
    text += "\ntheta_deg,phi_deg,Y_cd_m2,Y_stderr_cd_m2,paths,cpu_s\n";
    double total = 0.0;
    for (size_t d : only) {
      const double rel = est[d].xyz_stderr[1] / est[d].xyz[1];
      text += fmt::format("{},{},{:.9e},{:.6e},{},{:.1f}\n", SkyAngles()[d][0], SkyAngles()[d][1], est[d].xyz[1],
                          est[d].xyz_stderr[1], est[d].paths, seconds[d]);
      std::printf("%5.1f %5.1f  Y %.6g +- %.2f %%  %llu paths  %.0f s\n", SkyAngles()[d][0], SkyAngles()[d][1], est[d].xyz[1],
                  100 * rel, static_cast<unsigned long long>(est[d].paths), seconds[d]);
      total += seconds[d];
    }
    std::printf("%s sun %.1f deg: %.0f CPU s\n", atmosphere.c_str(), sun_zenith, total);
    WriteFileIfChanged(out, text);
  });
}
