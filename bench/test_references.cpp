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
//
// --delta-cone-deg X traces the delta-scaled medium instead (a diagnostic, not a reference): every
// component whose phase peaks above 30 sr^-1 (cloud droplets) has its phase flattened inside a cone
// of X deg and its scattering multiplied by 1 - f, f the flattened share (docs/sky-methods.md
// "orders": the medium `orders` builds its tables on). Against the true medium's reference it
// measures what the delta-approximation alone does to the sky, apart from any table:
//
//   build/test/bin/bench_test_references --atmosphere cloudy0 --sun-zenith-deg 85 --target-error 0.01
//       --delta-cone-deg 6.5 -o /tmp/cloudy0_sun85_delta.csv    (one command line)
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/cli.h"
#include "atmosphere/phase_peak.h"
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

// A phase function flattened inside a cone: P*(mu) = min-cap of P at cos(cone) for mu above it,
// divided by 1 - f so that it integrates to 1 (f = the share removed). Sampled by inverting its CDF
// tabulated on 20 000 angles uniform in theta (the flattened function has no peak finer than that).
class DeltaTruncatedPhase : public PhaseModel {
 public:
  DeltaTruncatedPhase(std::shared_ptr<const PhaseModel> base, size_t nw, double cone_deg)
      : base_(std::move(base)), cos_c_(std::cos(cone_deg * kDeg)), f_(nw), mu_(kN + 1), cdf_(nw, std::vector<double>(kN + 1)) {
    for (size_t i = 0; i <= kN; ++i) mu_[i] = std::cos(kPi * (1.0 - static_cast<double>(i) / kN));  // -1 .. 1
    for (size_t w = 0; w < nw; ++w) {
      std::vector<double>& c = cdf_[w];
      c[0] = 0.0;
      for (size_t i = 1; i <= kN; ++i) c[i] = c[i - 1] + kPi * (Capped(w, mu_[i - 1]) + Capped(w, mu_[i])) * (mu_[i] - mu_[i - 1]);
      f_[w] = 1.0 - c[kN];
      for (double& v : c) v /= c[kN];
    }
  }
  double f(size_t w) const { return f_[w]; }
  double Eval(size_t w, double mu) const override { return Capped(w, mu) / (1.0 - f_[w]); }
  double SampleMu(size_t w, double u) const override {
    const std::vector<double>& c = cdf_[w];
    const size_t i = std::min<size_t>(kN - 1, static_cast<size_t>(std::upper_bound(c.begin(), c.end(), u) - c.begin()) - 1);
    const double t = c[i + 1] > c[i] ? (u - c[i]) / (c[i + 1] - c[i]) : 0.5;
    return mu_[i] + t * (mu_[i + 1] - mu_[i]);
  }
  std::string Name() const override { return "delta-truncated(" + base_->Name() + ")"; }

 private:
  static constexpr size_t kN = 20000;
  double Capped(size_t w, double mu) const { return base_->Eval(w, std::min(mu, cos_c_)); }
  std::shared_ptr<const PhaseModel> base_;
  double cos_c_;
  std::vector<double> f_, mu_;
  std::vector<std::vector<double>> cdf_;
};

// The delta-scaled medium of the components peaking above kPeakedPhaseMin (the others unchanged).
void DeltaScale(AtmosphereModel* m, double cone_deg) {
  const size_t nw = m->wavelengths(), nl = m->levels();
  for (MediumComponent& c : m->components) {
    if (c.phase == nullptr) continue;
    if (PhasePeak(*c.phase, nw) <= kPeakedPhaseMin) continue;
    auto t = std::make_shared<DeltaTruncatedPhase>(c.phase, nw, cone_deg);
    for (size_t l = 0; l < nl; ++l) {
      for (size_t w = 0; w < nw; ++w) c.scattering[l * nw + w] *= 1.0 - t->f(w);
    }
    std::printf("%s: flattened inside %g deg, f %.3f at %g nm\n", c.name.c_str(), cone_deg, t->f(nw / 2), m->wavelength_nm[nw / 2]);
    c.phase = t;
  }
  m->Finalize();
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("bench_test_references", "A cached path reference for the sky-method tests (tests/transport/references/).");
  std::string atmosphere = "cloudy1", out;
  double sun_zenith = 30.0, target = 0.01;
  uint64_t max_paths = uint64_t{1} << 20, seed = 1;
  std::vector<size_t> only;
  double delta_cone = 0.0;
  cli.app().add_option("--atmosphere", atmosphere, "Atmosphere (atmospheres/<name>.yaml)");
  cli.app().add_option("--sun-zenith-deg", sun_zenith, "Sun zenith angle (deg)")->check(CLI::Range(0.0, 120.0));
  cli.app().add_option("--target-error", target, "Relative standard error of Y per direction")->check(CLI::Range(0.001, 0.5));
  cli.app().add_option("--max-paths", max_paths, "Path cap per direction (deep twilight needs more than the default 2^20)")
      ->check(CLI::Range(uint64_t{1024}, uint64_t{1} << 30));
  cli.app().add_option("--seed", seed, "Path tracer seed (another seed: an independent estimate)");
  cli.app().add_option("--directions", only, "Only these directions (indices 0-9 into the tests' ten), a check; the file then holds only them")
      ->check(CLI::Range(size_t{0}, size_t{9}))
      ->delimiter(',');
  cli.app()
      .add_option("--delta-cone-deg", delta_cone, "Trace the delta-scaled medium: droplets' phase flattened inside this cone (a diagnostic)")
      ->check(CLI::Range(0.5, 30.0));
  cli.app().add_option("-o,--output", out, "Output CSV")->required();
  return cli.Run(argc, argv, [&] {
    TestScene sc = LoadTestScene(atmosphere);
    if (delta_cone > 0.0) DeltaScale(&sc.model, delta_cone);  // its fingerprint then matches no test's scene
    const std::vector<double> fingerprint = SceneFingerprint(sc);
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
        "# source: bench_test_references --atmosphere {} --sun-zenith-deg {} --target-error {}{}{} (path tracer, seed {}, "
        "streams 300 + direction; the tests' scene, tests/transport/method_scenes.h); Y in cd/m^2, cpu_s on one thread\n",
        atmosphere, sun_zenith, target, max_paths == (uint64_t{1} << 20) ? std::string() : fmt::format(" --max-paths {}", max_paths),
        delta_cone > 0.0 ? fmt::format(" --delta-cone-deg {}", delta_cone) : std::string(), ps.seed);
    text += "# scene:";
    for (double v : fingerprint) text += fmt::format(" {:.9e}", v);
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
