// Mie tables: what a single sphere costs as the size parameter grows, with and without
// the amplitudes S1, S2 on the table's 2161-angle grid, and what whole particle-type tables cost
// on the pipeline's 95 wavelengths (360-830 nm, 5 nm) with the full phase grid, at 1 and 2 threads
// (the GT7 case study both as its five modes and as the 22-bin table made from them).
//
//   build/release/bin/bench_mie --benchmark_counters_tabular=true
//   build/release/bin/bench_mie --benchmark_filter=Table --benchmark_repetitions=3
// Counters: "terms" (Wiscombe's N); for tables "radii" (Mie evaluations over all
// wavelengths), "cpu_s" (process CPU time of one build, all threads) and "wl/s" (wavelengths per
// second of wall time). Goals: the GT7 five-mode table in <= 5 s wall on 2 cores, the water cloud
// in <= 10 s; BM_TableAccuracy measures what the tables' quadrature tolerance (1e-4) gives.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <numbers>

#include "optics/mie_angular.h"
#include "optics/mie_sphere.h"
#include "optics/polydisperse.h"

using namespace skybake::mie;

namespace {

std::filesystem::path Repo(const char* rel) { return std::filesystem::path(SKYBAKE_SOURCE_DIR) / rel; }

double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// One sphere, m = 1.33 + 1e-8 i (water), x = range(0); range(1) = 1: S1, S2 at the 2161 grid
// angles by the direct BH sum (mie_sphere.h Amplitudes), as `mie-tables sphere --angles-deg`.
void BM_SingleSphere(benchmark::State& state) {
  const double x = static_cast<double>(state.range(0));
  const bool angles = state.range(1) != 0;
  const PhaseGrid grid = StandardPhaseGrid();
  const std::vector<double> mu = angles ? grid.mu : std::vector<double>();
  MieWorkspace ws;
  MieCoefficients c;
  std::vector<Complex> s1, s2;
  for (auto _ : state) {
    ComputeCoefficients(x, Complex(1.33, 1e-8), c, ws);
    benchmark::DoNotOptimize(Efficiencies(c));
    if (angles) Amplitudes(c, mu, s1, s2);
    benchmark::ClobberMemory();
  }
  state.counters["terms"] = c.terms;
  state.SetLabel(angles ? "Q, g + S1, S2 at 2161 angles" : "Q, g");
}
BENCHMARK(BM_SingleSphere)
    ->ArgsProduct({{1, 10, 100, 1000, 10000}, {0, 1}})
    ->ArgNames({"x", "angles"})
    ->Unit(benchmark::kMicrosecond);

// The table path per radius: coefficients, efficiencies and the Gram-matrix update that replaces
// per-radius angle sums in size integrals (mie_angular.h); the angles are evaluated once per
// quadrature level, not per radius.
void BM_SphereInSizeIntegral(benchmark::State& state) {
  const double x = static_cast<double>(state.range(0));
  MieWorkspace ws;
  MieCoefficients c;
  ComputeCoefficients(x, Complex(1.33, 1e-8), c, ws);
  IntensityAccumulator acc(c.terms);
  for (auto _ : state) {
    ComputeCoefficients(x, Complex(1.33, 1e-8), c, ws);
    benchmark::DoNotOptimize(Efficiencies(c));
    acc.Add(c, 1.0);
  }
  acc.Scale(1.0);  // flush the last batch inside the measured run's scope of work
  state.counters["terms"] = c.terms;
  state.SetLabel("coefficients + Gram update");
}
BENCHMARK(BM_SphereInSizeIntegral)->Arg(1)->Arg(10)->Arg(100)->Arg(1000)->ArgName("x")->Unit(benchmark::kMicrosecond);

// A whole table on the pipeline grid with range(0) worker threads.
void BM_Table(benchmark::State& state, const char* file) {
  const ParticleType type = LoadParticleType(Repo(file));
  std::vector<double> wl;
  for (int i = 0; i <= 94; ++i) wl.push_back(360.0 + 5.0 * i);
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  long radii = 0;
  double cpu = 0.0;
  for (auto _ : state) {
    const double c0 = CpuSeconds();
    arena.execute([&] {
      const MieBuild b = BuildMieTable(type, wl, MieBuildOptions{});
      radii = 0;
      for (const MixtureIntegral& mi : b.integrals) radii += mi.radii;
      benchmark::DoNotOptimize(b.table.phase.data());
    });
    cpu = CpuSeconds() - c0;
  }
  state.counters["radii"] = static_cast<double>(radii);
  state.counters["cpu_s"] = cpu;
  state.counters["wl/s"] = benchmark::Counter(static_cast<double>(wl.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::string(file) + ", 95 wavelengths x 2161 angles");
}
BENCHMARK_CAPTURE(BM_Table, gt7_case_study, "particles/gt7_case_study.yaml")
    ->Arg(1)->Arg(2)->ArgName("threads")->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);
// The same aerosol as a measured 22-bin table (particles/gt7_case_study_22_bins.yaml, AERONET's
// radii): what reading a measurement "as is" costs against its five fitted modes.
BENCHMARK_CAPTURE(BM_Table, gt7_case_study_22_bins, "particles/gt7_case_study_22_bins.yaml")
    ->Arg(1)->Arg(2)->ArgName("threads")->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_Table, continental, "particles/continental.yaml")
    ->Arg(2)->ArgName("threads")->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_Table, water_cloud, "particles/water_cloud.yaml")
    ->Arg(2)->ArgName("threads")->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);

// The table's accuracy against a reference converged to 1e-6 (100x the table's tolerance) at
// 360, 595 and 830 nm: counters "ext", "sca" (largest relative error of C_ext, C_sca), "g"
// (largest absolute error) and "phase_l1" (largest int |P - P_ref| dOmega, trapezoid in mu on
// the table's grid), with "radii" and "radii_ref" (Mie evaluations of the table and of the
// reference). 2 threads.
void BM_TableAccuracy(benchmark::State& state, const char* file) {
  const ParticleType type = LoadParticleType(Repo(file));
  const std::vector<double> wl{360.0, 595.0, 830.0};
  tbb::task_arena arena(2);
  MieBuildOptions reference_options;
  reference_options.quadrature.tolerance = 1e-6;
  double ext = 0.0, sca = 0.0, g = 0.0, l1 = 0.0;
  long radii = 0, radii_ref = 0;
  for (auto _ : state) {
    arena.execute([&] {
      const MieBuild b = BuildMieTable(type, wl, MieBuildOptions{});
      const MieBuild r = BuildMieTable(type, wl, reference_options);
      const MieTable &t = b.table, &rt = r.table;
      for (size_t w = 0; w < wl.size(); ++w) {
        radii += b.integrals[w].radii;
        radii_ref += r.integrals[w].radii;
        ext = std::max(ext, std::abs(t.cext_m2[w] / rt.cext_m2[w] - 1.0));
        sca = std::max(sca, std::abs(t.csca_m2[w] / rt.csca_m2[w] - 1.0));
        g = std::max(g, std::abs(t.g[w] - rt.g[w]));
        double d = 0.0;
        for (size_t j = 0; j + 1 < t.mu.size(); ++j) {
          d += std::numbers::pi * (t.mu[j] - t.mu[j + 1]) *
               (std::abs(t.phase[w][j] - rt.phase[w][j]) + std::abs(t.phase[w][j + 1] - rt.phase[w][j + 1]));
        }
        l1 = std::max(l1, d);
      }
    });
  }
  state.counters["ext"] = ext;
  state.counters["sca"] = sca;
  state.counters["g"] = g;
  state.counters["phase_l1"] = l1;
  state.counters["radii"] = static_cast<double>(radii);
  state.counters["radii_ref"] = static_cast<double>(radii_ref);
  state.SetLabel(std::string(file) + ", 360/595/830 nm against tolerance 1e-6");
}
BENCHMARK_CAPTURE(BM_TableAccuracy, gt7_case_study, "particles/gt7_case_study.yaml")
    ->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_TableAccuracy, continental, "particles/continental.yaml")
    ->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_TableAccuracy, water_cloud, "particles/water_cloud.yaml")
    ->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
