// Generation time of each cloud texture of clouds/*.yaml, at 1 and 2 worker threads:
// the GT7 low-frequency volume (128^3 Perlin-Worley), the high-frequency volume (32^3 Worley),
// the RGBA shape volume (128^3, 4 channels), the cumulus map (256^2, including the weather
// field's CDF calibration) and the coverage texture. Times include normalisation and texel
// encoding (what noise-gen / cumulus-map do besides file I/O).
//
//   build/release/bin/bench_noise --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
// Reports wall time per texture and texels per second (counter "voxels/s"); with repetitions also
// the minimum ("_min"), the figure to quote when other processes share the cores.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <filesystem>

#include "lut/ktx2.h"
#include "noise/coverage.h"
#include "noise/cumulus.h"
#include "noise/volume.h"

using namespace skybake;
using namespace skybake::noise;

namespace {

std::filesystem::path Repo(const char* rel) { return std::filesystem::path(SKYBAKE_SOURCE_DIR) / rel; }

ktx2::Format KtxFormat(VolumeFormat f) {
  switch (f) {
    case VolumeFormat::kR8Unorm: return ktx2::R8Unorm();
    case VolumeFormat::kR16Sfloat: return ktx2::R16Sfloat();
    case VolumeFormat::kR8G8B8A8Unorm: return ktx2::R8G8B8A8Unorm();
  }
  return ktx2::R8Unorm();
}

void BM_Volume(benchmark::State& state, const char* file) {
  const VolumeSpec spec = LoadVolumeSpec(Repo(file));
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    arena.execute([&] {
      const GeneratedVolume g = GenerateVolume(spec);
      benchmark::DoNotOptimize(ktx2::EncodeTexels(KtxFormat(spec.format), g.volume.values));
    });
  }
  const double voxels = static_cast<double>(spec.resolution) * spec.resolution * spec.resolution;
  state.counters["voxels/s"] = benchmark::Counter(voxels, benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::to_string(spec.resolution) + "^3 x" + std::to_string(spec.channels.size()) + " " + FormatName(spec.format));
}

void BM_CumulusMap(benchmark::State& state) {
  const CumulusSpec spec = LoadCumulusSpec(Repo("clouds/cumulus.yaml"));
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    arena.execute([&] {
      const WeatherField field(spec.weather);  // includes the 2 x 512^2-sample CDF calibration
      const CumulusMap map = GenerateCumulusMap(spec, field);
      benchmark::DoNotOptimize(ktx2::EncodeTexels(ktx2::R8G8Unorm(), map.values));
    });
  }
  state.counters["voxels/s"] =
      benchmark::Counter(static_cast<double>(spec.resolution) * spec.resolution, benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::to_string(spec.resolution) + "^2 R8G8_UNORM");
}

void BM_CoverageTexture(benchmark::State& state) {
  const CoverageSpec spec = LoadCoverageSpec(Repo("clouds/coverage.yaml"));
  for (auto _ : state) {
    const CoverageTexture t = BuildCoverageTexture(spec);
    benchmark::DoNotOptimize(ktx2::EncodeTexels(ktx2::R8G8B8A8Unorm(), t.values));
  }
  state.SetLabel(std::to_string(spec.density_texels) + "x" + std::to_string(spec.altitude_texels) + " x" +
                 std::to_string(spec.types.size()) + " layers");
}

// The minimum over repetitions: the robust estimate when other processes share the 2 cores.
double Min(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

}  // namespace

BENCHMARK_CAPTURE(BM_Volume, gt7_low_128, "clouds/noise_low.yaml")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("min", Min);
BENCHMARK_CAPTURE(BM_Volume, gt7_high_32, "clouds/noise_high.yaml")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("min", Min);
BENCHMARK_CAPTURE(BM_Volume, shape_rgba_128, "clouds/noise_shape_rgba.yaml")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("min", Min);
BENCHMARK(BM_CumulusMap)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("min", Min);
BENCHMARK(BM_CoverageTexture)->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("min", Min);
BENCHMARK_MAIN();
