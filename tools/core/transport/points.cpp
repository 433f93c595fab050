#include "transport/points.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include "io/csv.h"
#include "io/error.h"
#include "io/fileio.h"
#include "transport/path_tracer.h"
#include "transport/random.h"
#include "transport/sky_render.h"

namespace skybake {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr uint64_t kBlockPaths = 64;

// Running mean and sum of squared deviations of several columns (Welford 1962), and the
// pairwise merge of two such (Chan, Golub & LeVeque 1979, eq. 2.1b).
struct Moments {
  uint64_t n = 0;
  std::vector<double> mean, m2;
  explicit Moments(size_t columns = 0) : mean(columns, 0.0), m2(columns, 0.0) {}
  void Add(const double* x) {
    ++n;
    const double nn = static_cast<double>(n);
    for (size_t c = 0; c < mean.size(); ++c) {
      const double delta = x[c] - mean[c];
      mean[c] += delta / nn;
      m2[c] += delta * (x[c] - mean[c]);
    }
  }
  void Merge(const Moments& b) {
    if (b.n == 0) return;
    if (n == 0) {
      *this = b;
      return;
    }
    const double na = static_cast<double>(n), nb = static_cast<double>(b.n), nt = na + nb;
    for (size_t c = 0; c < mean.size(); ++c) {
      const double delta = b.mean[c] - mean[c];
      mean[c] += delta * (nb / nt);
      m2[c] += b.m2[c] + delta * delta * (na * nb / nt);
    }
    n += b.n;
  }
  double StdErr(size_t c) const {
    if (n < 2) return 0.0;
    return std::sqrt(m2[c] / static_cast<double>(n - 1) / static_cast<double>(n));
  }
};

glm::dvec3 SunDirection(const PointGeometry& g) { return DirectionFromAngles(g.sun_zenith_deg * kPi / 180.0, 0.0); }
glm::dvec3 ViewDirection(const PointGeometry& g) {
  return DirectionFromAngles(g.view_zenith_deg * kPi / 180.0, g.relative_azimuth_deg * kPi / 180.0);
}

void SunTransmittance(const AtmosphereModel& m, const PointGeometry& g, const std::vector<size_t>& wl, PointResult* r) {
  std::vector<double> t;
  TransmittanceToSpace(m, g.observer_altitude_m, g.sun_zenith_deg * kPi / 180.0, &t);
  r->sun_transmittance.clear();
  for (size_t w : wl) r->sun_transmittance.push_back(t[w]);
}

// One row by the path tracer. Columns of the moments: k radiances, k order-1 parts, Y.
PointResult PathRow(const PathTracer& tracer, const PointGeometry& g, const std::vector<size_t>& wl) {
  const AtmosphereModel& m = tracer.model();
  const PathTracerSettings& s = tracer.settings();
  const size_t k = wl.size();
  const glm::dvec3 position(0.0, 0.0, m.bottom_radius_m + g.observer_altitude_m);
  const glm::dvec3 start = tracer.StartPoint(position);
  const glm::dvec3 sun = SunDirection(g), view = ViewDirection(g);
  const uint64_t key = PointStreamKey(g);
  const uint64_t spectral_stream = key, color_stream = SplitMix64(key ^ 0x59C0108E9A3B17D5ull);
  const double floor_spectral = SpectralErrorFloor(s.absolute_error_floor);
  Moments total(2 * k + 1);
  uint64_t target = std::min(s.max_paths, std::max<uint64_t>(kBlockPaths, (s.min_paths + kBlockPaths - 1) / kBlockPaths * kBlockPaths));
  for (;;) {
    const uint64_t from = total.n;
    const uint64_t blocks = (target - from + kBlockPaths - 1) / kBlockPaths;
    std::vector<Moments> part(blocks, Moments(2 * k + 1));
    tbb::parallel_for(uint64_t{0}, blocks, [&](uint64_t b) {
      std::vector<double> x(2 * k + 1);
      double L[PathTracer::kMaxWavelengths], L1[PathTracer::kMaxWavelengths], xyz[3];
      const uint64_t end = std::min(target, from + (b + 1) * kBlockPaths);
      for (uint64_t n = from + b * kBlockPaths; n < end; ++n) {
        Pcg32 rng(s.seed, spectral_stream, n);
        tracer.TracePath(start, view, sun, wl.data(), static_cast<int>(k), rng, L,
                         std::numeric_limits<double>::infinity(), true, L1);
        tracer.ColorPath(position, view, sun, color_stream, n, xyz);
        for (size_t j = 0; j < k; ++j) {
          x[j] = L[j];
          x[k + j] = L1[j];
        }
        x[2 * k] = xyz[1];
        part[b].Add(x.data());
      }
    });
    for (const Moments& p : part) total.Merge(p);
    bool converged = true;
    for (size_t c = 0; c < 2 * k + 1 && converged; ++c) {
      if (c >= k && c < 2 * k) continue;  // the order-1 parts report their error only
      const double floor = c == 2 * k ? s.absolute_error_floor : floor_spectral;
      const bool zero_so_far = total.mean[c] == 0.0 && total.m2[c] == 0.0;
      converged = !zero_so_far && total.StdErr(c) <= std::max(s.target_relative_error * std::abs(total.mean[c]), floor);
    }
    if ((total.n >= s.min_paths && converged) || total.n >= s.max_paths) break;
    target = std::min(s.max_paths, 2 * total.n);
  }
  PointResult r;
  for (size_t j = 0; j < k; ++j) {
    r.radiance.push_back(total.mean[j]);
    r.radiance_stderr.push_back(total.StdErr(j));
    r.single.push_back(total.mean[k + j]);
    r.single_stderr.push_back(total.StdErr(k + j));
  }
  r.y_cd_m2 = total.mean[2 * k];
  r.y_stderr_cd_m2 = total.StdErr(2 * k);
  r.paths = total.n;
  SunTransmittance(m, g, wl, &r);
  return r;
}

}  // namespace

uint64_t PointStreamKey(const PointGeometry& g) {
  uint64_t h = 0x2545F4914F6CDD1Dull;
  for (double v : {g.sun_zenith_deg, g.view_zenith_deg, g.relative_azimuth_deg, g.observer_altitude_m}) {
    h = SplitMix64(h ^ std::bit_cast<uint64_t>(v + 0.0));  // + 0.0: -0 and 0 are one geometry
  }
  return h;
}

double SpectralErrorFloor(double y_floor_cd_m2) { return y_floor_cd_m2 / (683.0 * 106.857); }

PointsInput ParsePointGeometries(const CsvTable& csv, double default_altitude_m, double top_m) {
  PointsInput in;
  Diagnostics d;
  std::vector<double> sza = csv.Numbers("sun_zenith_deg", d);
  std::vector<double> vza = csv.Numbers("view_zenith_deg", d);
  std::vector<double> raz = csv.Numbers("relative_azimuth_deg", d);
  std::vector<double> alt(csv.rows(), default_altitude_m);
  for (const std::string& c : csv.columns()) {
    if (c.rfind("observer_altitude_", 0) == 0) in.altitude_column = c;
  }
  if (!in.altitude_column.empty()) {
    std::optional<CsvTable::SiColumn> a = csv.NamedColumnIn(in.altitude_column, Quantity::kLength, d);
    if (a) alt = a->values;
  }
  d.ThrowIfAny();
  for (size_t r = 0; r < csv.rows(); ++r) {
    if (!(sza[r] >= 0 && sza[r] <= 180)) d.Add(csv.LocOfRow(r), "sun_zenith_deg must be in 0-180");
    if (!(vza[r] >= 0 && vza[r] <= 180)) d.Add(csv.LocOfRow(r), "view_zenith_deg must be in 0-180");
    if (!(raz[r] >= -360 && raz[r] <= 360)) d.Add(csv.LocOfRow(r), "relative_azimuth_deg must be in -360-360");
    if (!(alt[r] >= 0 && alt[r] < top_m)) {
      d.Add(csv.LocOfRow(r), fmt::format("{}: the observer must be inside the atmosphere (0 to {:g} m), got {:g} m",
                                         in.altitude_column.empty() ? "observer altitude" : in.altitude_column,
                                         top_m, alt[r]));
    }
    in.rows.push_back({sza[r], vza[r], raz[r], alt[r]});
  }
  d.ThrowIfAny();
  return in;
}

PointsInput LoadPointsInput(const Scene& scene, const PointsOptions& o) {
  PointsInput in = ParsePointGeometries(CsvTable::Load(o.geometry), scene.spec.observer_altitude_m,
                                        scene.model.altitude_m.back());
  if (o.wavelengths_nm.empty()) throw UsageError("--wavelengths-out: expected at least one wavelength");
  if (o.wavelengths_nm.size() > static_cast<size_t>(PathTracer::kMaxWavelengths)) {
    throw UsageError(fmt::format("--wavelengths-out: at most {} wavelengths, got {}", PathTracer::kMaxWavelengths,
                                 o.wavelengths_nm.size()));
  }
  for (double w : o.wavelengths_nm) {
    auto it = std::find_if(scene.grid.wavelength_nm().begin(), scene.grid.wavelength_nm().end(),
                           [&](double g) { return std::abs(g - w) < 1e-9; });
    if (it == scene.grid.wavelength_nm().end()) throw UsageError(fmt::format("--wavelengths-out: {} nm is not on the grid", w));
    in.wavelengths.push_back(static_cast<size_t>(it - scene.grid.wavelength_nm().begin()));
  }
  return in;
}

PointsResult EvaluatePoints(const Scene& scene, const PointsOptions& o, const PointsInput& in, const ProgressFn& progress) {
  PointsResult res;
  res.rows.resize(in.rows.size());
  std::atomic<size_t> done{0};
  auto tick = [&] {
    const size_t n = ++done;
    ReportProgress(progress, "points", static_cast<double>(n) / static_cast<double>(in.rows.size()));
  };
  if (o.method == "path") {
    if (o.method_options.spectral_stride != 1) throw UsageError("--spectral-stride: applies to the deterministic methods, not path");
    PathTracerSettings s = scene.tracer;
    s.wavelength_mis = true;
    if (o.paths > 0) s.min_paths = s.max_paths = o.paths;
    const PathTracer tracer(scene.model, scene.xyz_weights, s);
    tbb::parallel_for(size_t{0}, in.rows.size(), [&](size_t r) {
      res.rows[r] = PathRow(tracer, in.rows[r], in.wavelengths);
      tick();
    });
    res.has_single = scene.tracer.illumination == Illumination::kSun;
    res.description = fmt::format("method: path\nwavelength_mis: true\npaths: {}\n",
                                  o.paths > 0 ? std::to_string(o.paths) : std::string("adaptive"));
    return res;
  }
  // Deterministic: one method per distinct observer altitude.
  std::map<double, std::vector<size_t>> by_altitude;
  for (size_t r = 0; r < in.rows.size(); ++r) by_altitude[in.rows[r].observer_altitude_m].push_back(r);
  const size_t nw = scene.model.wavelengths();
  res.has_single = true;
  for (const auto& group : by_altitude) {
    // Named copies, not structured bindings: the lambda below captures them (clang 14, the
    // sanitizer build's compiler, does not capture structured bindings).
    const double alt = group.first;
    const std::vector<size_t>& rows = group.second;
    SkyMethodOptions mo = o.method_options;
    mo.observer_altitude_m = alt;
    std::unique_ptr<SkyMethod> method = MakeSkyMethod(o.method, scene.model, mo, progress);
    ++res.methods_built;
    if (res.description.empty()) res.description = method->Describe();
    std::atomic<bool> single_known{true};
    tbb::parallel_for(size_t{0}, rows.size(), [&](size_t i) {
      const PointGeometry& g = in.rows[rows[i]];
      const glm::dvec3 v = ViewDirection(g);
      const std::vector<std::array<double, 3>> dirs = {{v.x, v.y, v.z}};
      const double theta_s = g.sun_zenith_deg * kPi / 180.0;
      std::vector<double> L, L1;
      method->Radiance(alt, theta_s, dirs, &L);
      const bool single = method->SingleScatteringRadiance(alt, theta_s, dirs, &L1);
      if (!single) single_known = false;
      PointResult& r = res.rows[rows[i]];
      for (size_t w : in.wavelengths) {
        r.radiance.push_back(L[w]);
        r.radiance_stderr.push_back(0.0);
        r.single.push_back(single ? L1[w] : 0.0);
        r.single_stderr.push_back(0.0);
      }
      for (size_t w = 0; w < nw; ++w) r.y_cd_m2 += scene.xyz_weights[w][1] * L[w];
      SunTransmittance(scene.model, g, in.wavelengths, &r);
      tick();
    });
    res.has_single = res.has_single && single_known;
  }
  return res;
}

std::string PointsCsv(const Scene& scene, const PointsOptions& o, const PointsInput& in, const PointsResult& res) {
  const std::string how =
      o.method == "path"
          ? (o.paths > 0 ? fmt::format("path tracer, {} paths per row", o.paths)
                         : fmt::format("path tracer, target relative error {:g}, {} to {} paths per row",
                                       scene.tracer.target_relative_error, scene.tracer.min_paths, scene.tracer.max_paths))
          : fmt::format("method {}, quality {}, built once per observer altitude ({} built)", o.method,
                        QualityName(o.method_options.quality), res.methods_built);
  std::string out = "# source: sky-render points (" + how +
                    "); relative_azimuth_deg = 0 looks towards the sun's azimuth; L/E0 = radiance per unit "
                    "extraterrestrial irradiance on a surface normal to the sun (sr^-1); single = the order-1 part; "
                    "sun_transmittance = from the observer to space towards the sun's centre\n";
  // The method's resolved settings (e.g. orders_computed), one "# key: value" line each.
  std::stringstream description(res.description);
  for (std::string line; std::getline(description, line);) {
    if (!line.empty()) out += "# " + line + "\n";
  }
  out += "sun_zenith_deg,view_zenith_deg,relative_azimuth_deg";
  if (!in.altitude_column.empty()) out += ",observer_altitude_m";
  for (double w : o.wavelengths_nm) {
    out += fmt::format(",radiance_{0}nm_W_m2_sr_nm,stderr_{0}nm_W_m2_sr_nm,radiance_over_e0_{0}nm_per_sr,"
                       "stderr_over_e0_{0}nm_per_sr",
                       w);
    if (res.has_single) out += fmt::format(",single_{0}nm_W_m2_sr_nm,single_stderr_{0}nm_W_m2_sr_nm", w);
    out += fmt::format(",sun_transmittance_{0}nm", w);
  }
  out += ",Y_cd_m2,Y_stderr_cd_m2,paths\n";
  for (size_t r = 0; r < in.rows.size(); ++r) {
    const PointGeometry& g = in.rows[r];
    const PointResult& p = res.rows[r];
    out += fmt::format("{},{},{}", FormatExact(g.sun_zenith_deg), FormatExact(g.view_zenith_deg),
                       FormatExact(g.relative_azimuth_deg));
    if (!in.altitude_column.empty()) out += "," + FormatExact(g.observer_altitude_m);
    for (size_t j = 0; j < in.wavelengths.size(); ++j) {
      const double e0 = scene.model.sun.irradiance[in.wavelengths[j]];
      out += fmt::format(",{:.6e},{:.3e},{:.6e},{:.3e}", p.radiance[j], p.radiance_stderr[j], p.radiance[j] / e0,
                         p.radiance_stderr[j] / e0);
      if (res.has_single) out += fmt::format(",{:.6e},{:.3e}", p.single[j], p.single_stderr[j]);
      out += fmt::format(",{:.6e}", p.sun_transmittance[j]);
    }
    out += fmt::format(",{:.6e},{:.3e},{}\n", p.y_cd_m2, p.y_stderr_cd_m2, p.paths);
  }
  return out;
}

void WritePoints(const Scene& scene, const PointsOptions& o, const std::filesystem::path& path, const ProgressFn& progress) {
  const PointsInput in = LoadPointsInput(scene, o);
  const PointsResult res = EvaluatePoints(scene, o, in, progress);
  WriteFileIfChanged(path, PointsCsv(scene, o, in, res));
}

}  // namespace skybake
