// The cost and the error of stopping `orders` after fewer scattering orders (docs/sky-methods.md
// "Thick clouds: where the orders stop"): for one atmosphere and quality, the multiple-scattering
// solve with the orders capped at each of --orders (the geometric tail taken at the cap) against
// the solve capped at --reference-orders (with --reference-all-orders: every order to the cap,
// then the tail, so that the reference is not cut short by the stopping rule), per sun zenith angle: RMS and largest relative
// difference of Y over the chart's 91 directions (transport/sky_error.h), the orders done, whether
// the tail was taken, and the build's wall time.
//
//   build/test/bin/bench_orders_tail [--atmosphere cloudy5] [--quality high] [--orders 10,15,20,30,40]
//                                    [--reference-orders 150] [--reference-all-orders]
//                                    [--sun-zenith-deg 30,70,85,90,95]
//
// The scene is the tests' (tests/transport/method_scenes.h: the atmosphere's Mie tables built in
// process on a 20 nm grid, 380-780 nm, 21 samples), so that the figures need no baked outputs/.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "io/cli.h"
#include "transport/method_scenes.h"
#include "transport/sky_error.h"
#include "transport/sky_method.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

struct Solve {
  std::vector<std::vector<double>> y;  // per sun angle, per direction (cd/m^2)
  double build_s = 0.0;
  std::string orders_done, tail;
};

// The values of every `...key: value` line in a method's Describe() text, joined by '/' (the
// twilight split describes each of its two solves).
std::string Field(const std::string& desc, const std::string& key) {
  std::string out;
  for (size_t at = desc.find(key + ": "); at != std::string::npos; at = desc.find(key + ": ", at + 1)) {
    const size_t from = at + key.size() + 2;
    out += (out.empty() ? "" : "/") + desc.substr(from, desc.find('\n', from) - from);
  }
  return out;
}

Solve Run(const TestScene& sc, Quality q, int orders, bool all_orders, const std::vector<double>& suns, const SkyDirections& D) {
  SkyMethodOptions o;
  o.quality = q;
  o.orders = orders;
  if (all_orders) {  // every order to the cap, then the dominant mode's tail there
    o.table_size["early_tail"] = 0;
    o.order_tolerance = 1e-9;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto method = MakeSkyMethod("orders", sc.model, o, {});
  Solve s;
  s.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string desc = method->Describe();
  s.orders_done = Field(desc, "orders_computed");
  s.tail = Field(desc, "tail_extrapolated");
  const size_t nw = sc.model.wavelengths();
  for (double sun : suns) {
    std::vector<double> L;
    method->Radiance(0.0, sun * kDeg, D.dirs, &L);
    std::vector<double> y(D.dirs.size());
    for (size_t d = 0; d < D.dirs.size(); ++d) y[d] = sc.Y(&L[d * nw]);
    s.y.push_back(std::move(y));
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("bench_orders_tail", "The error and cost of capping the orders of `orders` (docs/sky-methods.md).");
  std::string atmosphere = "cloudy5", quality = "high";
  std::vector<int> caps = {10, 15, 20, 30, 40};
  int reference = 150;
  std::vector<double> suns = {30, 70, 85, 90, 95};
  bool reference_all = false;
  cli.app().add_option("--atmosphere", atmosphere, "Atmosphere (atmospheres/<name>.yaml)");
  cli.app().add_option("--quality", quality, "low, medium or high");
  cli.app().add_option("--orders", caps, "Order caps to measure")->delimiter(',')->check(CLI::Range(2, 1000));
  cli.app().add_option("--reference-orders", reference, "Order cap of the reference solve")->check(CLI::Range(2, 1000));
  cli.app().add_flag("--reference-all-orders", reference_all, "The reference computes every order to its cap and takes its tail there");
  cli.app().add_option("--sun-zenith-deg", suns, "Sun zenith angles (deg)")->delimiter(',')->check(CLI::Range(0.0, 120.0));
  return cli.Run(argc, argv, [&] {
    const TestScene sc = LoadTestScene(atmosphere);
    const Quality q = ParseQuality(quality, "quality");
    const SkyDirections D = ChartDirections();
    const Solve ref = Run(sc, q, reference, reference_all, suns, D);
    std::printf("# %s, %s, reference: cap %d, orders done %s, tail %s, build %.1f s\n", atmosphere.c_str(), quality.c_str(),
                reference, ref.orders_done.c_str(), ref.tail.c_str(), ref.build_s);
    std::printf("cap,orders_done,tail,build_s");
    for (double sun : suns) std::printf(",rms_%g,max_%g", sun, sun);
    std::printf("\n");
    for (int cap : caps) {
      const Solve s = Run(sc, q, cap, false, suns, D);
      std::printf("%d,%s,%s,%.1f", cap, s.orders_done.c_str(), s.tail.c_str(), s.build_s);
      for (size_t i = 0; i < suns.size(); ++i) {
        double sum = 0.0, wsum = 0.0, mx = 0.0;
        for (size_t d = 0; d < D.dirs.size(); ++d) {
          if (!(ref.y[i][d] > 0.0)) continue;
          const double e = s.y[i][d] / ref.y[i][d] - 1.0;
          sum += D.solid_angle_sr[d] * e * e;
          wsum += D.solid_angle_sr[d];
          if (std::abs(e) > std::abs(mx)) mx = e;
        }
        std::printf(",%.3f%%,%+.3f%%", 100.0 * std::sqrt(sum / wsum), 100.0 * mx);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  });
}
