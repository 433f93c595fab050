// bench_sky_methods: cost per view ray of the sky methods on the clear atmosphere (95 wavelengths,
// continental aerosol from outputs/mie), one thread:
//   - the slow single-scattering quadrature (transport/single_scattering.h, 250 m pieces, point
//     sun), the reference of the fast march;
//   - `single` at low / medium / high, `ms-approx` (render only; the LUT build is timed apart),
//     `analytic`;
//   - the table builds: transmittance (per quality) and the multiple-scattering LUT.
// Directions: daylight (sun 30 deg, view 60 deg) and a sunset horizon (sun 90 deg, view 89 deg).
//   build/release/bin/bench_sky_methods --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <filesystem>
#include <memory>
#include <numbers>

#include "transport/method_ms_approx.h"
#include "transport/method_single.h"
#include "transport/path_tracer.h"
#include "transport/single_scattering.h"
#include "transport/sky_scene.h"

using namespace skybake;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

const Scene& Clear() {
  static const Scene s = [] {
    SceneOptions o;
    o.atmosphere = SKYBAKE_SOURCE_DIR "/atmospheres/clear.yaml";
    o.mie_dir = SKYBAKE_SOURCE_DIR "/outputs/mie";
    return LoadScene(o, {});
  }();
  return s;
}

struct Geometry {
  double sun, view;
};
const Geometry kGeometry[] = {{30, 60}, {90, 89}};

void SingleSlow(benchmark::State& state) {
  const AtmosphereModel& m = Clear().model;
  const Geometry g = kGeometry[state.range(0)];
  std::vector<size_t> all(m.wavelengths());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  SingleScatteringSettings s;
  s.max_piece_m = 250;
  s.disk_rings = 0;
  const glm::dvec3 x(0, 0, m.bottom_radius_m + 1.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        SingleScattering(m, x, DirectionFromAngles(g.view * kDeg, 0.5), DirectionFromAngles(g.sun * kDeg, 0), all, s));
  }
}
BENCHMARK(SingleSlow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void Method(benchmark::State& state, const char* name, const char* quality) {
  const Geometry g = kGeometry[state.range(0)];
  SkyMethodOptions o;
  o.quality = ParseQuality(quality, "quality");
  const std::unique_ptr<SkyMethod> method = MakeSkyMethod(name, Clear().model, o, {});
  const double t = g.view * kDeg;
  const std::vector<std::array<double, 3>> dirs = {{std::sin(t) * std::cos(0.5), std::sin(t) * std::sin(0.5), std::cos(t)}};
  std::vector<double> L;
  for (auto _ : state) {
    method->Radiance(0.0, g.sun * kDeg, dirs, &L);
    benchmark::DoNotOptimize(L.data());
  }
}
BENCHMARK_CAPTURE(Method, single_low, "single", "low")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Method, single_medium, "single", "medium")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Method, single_high, "single", "high")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Method, ms_approx_medium, "ms-approx", "medium")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Method, analytic_low, "analytic", "low")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Method, analytic_medium, "analytic", "medium")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void TransmittanceTableBuild(benchmark::State& state) {
  const AtmosphereModel& m = Clear().model;
  LevelTables t(m);
  for (auto _ : state) {
    TransmittanceTable table(t, static_cast<int>(state.range(0)), static_cast<int>(state.range(0) / 4));
    benchmark::DoNotOptimize(&table);
  }
}
BENCHMARK(TransmittanceTableBuild)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);

void MsLutBuild(benchmark::State& state, const char* quality) {
  const MsApproxSettings s = MsApproxPreset(ParseQuality(quality, "quality"));
  const SingleScatteringModel ss(Clear().model, s.march);
  for (auto _ : state) {
    MultipleScatteringLut lut(ss, s, {});
    benchmark::DoNotOptimize(&lut);
  }
}
BENCHMARK_CAPTURE(MsLutBuild, low, "low")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(MsLutBuild, medium, "medium")->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
