#include "fog/fog_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "color/color.h"
#include "fog/fog_evaluator.h"
#include "fog/fog_shard.h"
#include "io/error.h"
#include "io/text_list.h"
#include "io/yaml.h"
#include "transport/path_tracer.h"
#include "transport/view_segment.h"

namespace fs = std::filesystem;

namespace skybake::fog {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Disjoint path-tracer stream ranges per product (Pcg32 streams are 64-bit).
constexpr uint64_t kSliceStreams = uint64_t{1} << 50;
constexpr uint64_t kTableStreams = uint64_t{2} << 50;

std::array<double, 3> DirOf(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * kDeg, a = azimuth_deg * kDeg;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

// Evaluates the fog (and its stderr) of one view segment for several directions with either
// renderer; xyz in the scene observer's XYZ.
class SegmentRenderer {
 public:
  SegmentRenderer(const Scene& scene, const FogRenderOptions& o, double observer_altitude_m, const ProgressFn& progress)
      : scene_(scene), h_(observer_altitude_m) {
    if (o.method == "path") {
      tracer_ = std::make_unique<PathTracer>(scene.model, scene.xyz_weights, scene.tracer);
      description_ = "method: path\n";
    } else {
      SkyMethodOptions mo = o.method_options;
      mo.observer_altitude_m = h_;
      mo.segments = true;
      method_ = MakeSkyMethod(o.method, scene.model, mo, progress);
      if (!method_->SupportsSegments()) {
        throw UsageError("--method " + o.method + " does not render view segments (fog); use orders or path");
      }
      description_ = method_->Describe();  // YAML starting with "method: <name>"
    }
  }
  const std::string& description() const { return description_; }

  // out: per direction {X, Y, Z, Y_stderr}.
  void Render(double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs, const ViewSegment& seg,
              uint64_t stream_base, std::vector<std::array<double, 4>>* out) const {
    out->assign(dirs.size(), {0, 0, 0, 0});
    const AtmosphereModel& m = scene_.model;
    const size_t nw = m.wavelengths();
    if (method_) {
      std::vector<double> L;
      method_->SegmentRadiance(h_, sun_zenith_rad, dirs, seg, &L);
      for (size_t d = 0; d < dirs.size(); ++d) {
        for (size_t w = 0; w < nw; ++w) {
          for (size_t c = 0; c < 3; ++c) (*out)[d][c] += scene_.xyz_weights[w][c] * L[d * nw + w];
        }
      }
      return;
    }
    const glm::dvec3 position(0.0, 0.0, m.bottom_radius_m + h_);
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
    for (size_t d = 0; d < dirs.size(); ++d) {
      const double t_end = SegmentEnd(m, h_, dirs[d][2], seg);
      const glm::dvec3 dir = glm::normalize(glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]));
      const ColorEstimate e = tracer_->SegmentRadiance(position, dir, sun, t_end, stream_base + d, seg.single_scattering);
      (*out)[d] = {e.xyz[0], e.xyz[1], e.xyz[2], e.xyz_stderr[1]};
    }
  }

 private:
  const Scene& scene_;
  double h_;
  std::unique_ptr<PathTracer> tracer_;
  std::unique_ptr<SkyMethod> method_;
  std::string description_;
};

void CheckSize(int v, int lo, int hi, const std::string& what) {
  if (v < lo || v > hi) throw UsageError(fmt::format("{}: expected {} to {}, got {}", what, lo, hi, v));
}

}  // namespace

std::string FogTablePartName(double sun_zenith_deg) { return fmt::format("depth.sza_{:06.2f}", sun_zenith_deg); }
std::string FogSlicePartName(size_t k, double sun_zenith_deg) {
  return fmt::format("fog.slice_{:02d}.sza_{:06.2f}", k, sun_zenith_deg);
}

std::vector<double> DepthGrid(int n) {
  std::vector<double> x;
  for (int j = 1; j <= n; ++j) {
    const double u = static_cast<double>(j) / n;
    x.push_back(j == n ? 1.0 : u * u * u);
  }
  return x;
}

std::vector<double> ElevationGridDeg(int m) {
  std::vector<double> e;
  for (int i = 0; i < m; ++i) {
    const double v = static_cast<double>(i) / (m - 1);
    e.push_back(i == m - 1 ? 90.0 : 90.0 * v * v);
  }
  return e;
}

FogRender RenderFog(const Scene& scene, const FogRenderOptions& o, const ProgressFn& progress) {
  const AtmosphereModel& m = scene.model;
  if (!scene.spec.planet) throw InputError(FileLoc{scene.spec.file.string(), 0}, "fog renders need the 'planet' section");
  const SkyMethodEntry* entry = FindSkyMethod(o.method);
  if (o.method != "path" && !(entry && entry->segments)) {
    throw UsageError("--method " + o.method + " does not render view segments (fog); use " +
                     TextList(SegmentMethodNames(), ", ") + " or path");
  }
  const double h = o.observer_altitude_m >= 0.0 ? o.observer_altitude_m : scene.spec.observer_altitude_m;
  const double top = m.top_radius_m - m.bottom_radius_m;
  if (!(o.cut_altitude_m <= top)) {
    throw UsageError(fmt::format("--cut-altitude-km: {} km is above the top of the atmosphere ({} km)",
                                 FormatExact(o.cut_altitude_m / 1e3), FormatExact(top / 1e3)));
  }
  const FogGeometry geo(m.bottom_radius_m, h, o.cut_altitude_m);
  CheckSize(o.lut_width, 2, 4096, "--lut-size width");
  CheckSize(o.lut_height, 2, 4096, "--lut-size height");
  CheckSize(o.attenuation_width, 2, 4096, "--attenuation-size width");
  CheckSize(o.attenuation_height, 2, 4096, "--attenuation-size height");
  CheckSize(o.elevations, 2, 1000, "--elevations");
  CheckSize(o.depths, 1, 1000, "--depths");
  if (o.azimuth_deg.empty() || o.sun_zenith_deg.empty()) throw UsageError("--azimuths-deg and --sun-zenith-deg need at least one angle");
  for (double a : o.azimuth_deg) {
    if (!(a >= 0.0 && a <= 180.0)) throw UsageError(fmt::format("--azimuths-deg: {} is outside 0-180", a));
  }
  std::set<std::string> names;
  for (double z : o.sun_zenith_deg) {
    if (!(z >= 0.0 && z <= 180.0)) throw UsageError(fmt::format("--sun-zenith-deg: {} is outside 0-180", z));
    if (!names.insert(FogTablePartName(z)).second) throw UsageError(fmt::format("--sun-zenith-deg: {} is listed twice", z));
  }

  FogRender r;
  r.atmosphere = scene.spec.name;
  r.method = o.method;
  r.observer = ObserverName(scene.observer);
  r.shard = o.shard;
  r.planet_radius_m = m.bottom_radius_m;
  r.top_altitude_m = top;
  r.observer_altitude_m = h;
  r.cut_altitude_m = o.cut_altitude_m;
  r.wavelength_nm = m.wavelength_nm;
  r.sun_e0 = m.sun.irradiance;
  const size_t nw = m.wavelengths();

  SegmentRenderer renderer(scene, o, h, progress);
  r.method_description = renderer.description();

  // ---- LUT slices (x = 1).
  r.lut_width = o.lut_width;
  r.lut_height = o.lut_height;
  r.time = gt7::TimeMapping::FromName(o.time_mapping, scene.spec.planet->radius_m, scene.spec.planet->top_m, h);
  r.time_mapping_name = o.time_mapping;
  r.slice_zenith_deg = r.time.SliceZenithDeg();
  r.texel_grid = o.texel_grid;
  const gt7::Gt7SkyMapping mapping = r.mapping();
  const size_t texels = static_cast<size_t>(r.lut_width) * r.lut_height;
  const size_t n_slices = r.slice_zenith_deg.size();
  r.slice_xyz.assign(n_slices, std::vector<float>(texels * 3, 0.0f));
  r.slice_shadowed_xyz.assign(n_slices, std::vector<float>(texels * 3, 0.0f));
  r.slice_y_stderr.assign(n_slices, std::vector<float>(texels, 0.0f));
  // The shard's tasks (fog/fog_shard.h); every element keeps its stream and bytes.
  const FogShardRange own = FogShardRangeOf(o.shard, n_slices, o.sun_zenith_deg.size());
  std::atomic<size_t> done{0};
  const size_t row_begin = own.slice_begin * static_cast<size_t>(r.lut_height);
  const size_t row_end = own.slice_end * static_cast<size_t>(r.lut_height);
  const size_t slice_rows = std::max<size_t>(1, row_end - row_begin);
  tbb::parallel_for(tbb::blocked_range<size_t>(row_begin, row_end, 1), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t row = range.begin(); row != range.end(); ++row) {
      const size_t k = row / static_cast<size_t>(r.lut_height);
      const int y = static_cast<int>(row % static_cast<size_t>(r.lut_height));
      const double ts = r.slice_zenith_deg[k] * kDeg;
      std::vector<std::array<double, 3>> dirs;
      for (int x = 0; x < r.lut_width; ++x) {
        std::optional<std::array<double, 3>> d = mapping.TexelDirection(x, y, ts);
        SKYBAKE_CHECK(d.has_value());
        dirs.push_back(ClampToHorizon(*d));
      }
      for (int shadowed = 0; shadowed < 2; ++shadowed) {
        ViewSegment seg;
        seg.max_altitude_m = o.cut_altitude_m;
        seg.single_scattering = shadowed == 0;
        const uint64_t base = kSliceStreams + ((k * texels + static_cast<size_t>(y) * r.lut_width) * 2 + shadowed) *
                                                  static_cast<uint64_t>(r.lut_width);
        std::vector<std::array<double, 4>> out;
        renderer.Render(ts, dirs, seg, base, &out);
        std::vector<float>& dst = shadowed ? r.slice_shadowed_xyz[k] : r.slice_xyz[k];
        for (int x = 0; x < r.lut_width; ++x) {
          const size_t t = static_cast<size_t>(y) * r.lut_width + x;
          for (int c = 0; c < 3; ++c) dst[t * 3 + c] = static_cast<float>(out[x][c]);
          if (!shadowed) r.slice_y_stderr[k][t] = static_cast<float>(out[x][3]);
        }
      }
      const size_t n = ++done;
      if (progress) progress("fog LUT slices", static_cast<double>(n) / slice_rows);
    }
  });

  // ---- Depth tables.
  r.depth_x = DepthGrid(o.depths);
  r.azimuth_deg = o.azimuth_deg;
  r.elevation_deg = ElevationGridDeg(o.elevations);
  const size_t ne = r.elevation_deg.size(), na = r.azimuth_deg.size(), nx = r.depth_x.size();
  for (double sza : o.sun_zenith_deg) {
    FogDepthTable t;
    t.sun_zenith_deg = sza;
    t.xyz.assign(ne * na * nx * 3, 0.0f);
    t.shadowed_xyz.assign(ne * na * nx * 3, 0.0f);
    t.y_stderr.assign(ne * na * nx, 0.0f);
    t.shadowed_y_stderr.assign(ne * na * nx, 0.0f);
    r.tables.push_back(std::move(t));
  }
  const size_t task_begin = own.table_begin * ne * nx, task_end = own.table_end * ne * nx;
  const size_t tasks = std::max<size_t>(1, task_end - task_begin);
  done = 0;
  tbb::parallel_for(tbb::blocked_range<size_t>(task_begin, task_end, 1), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t task = range.begin(); task != range.end(); ++task) {
      const size_t s = task / (ne * nx), e = (task / nx) % ne, j = task % nx;
      FogDepthTable& t = r.tables[s];
      std::vector<std::array<double, 3>> dirs;
      for (double a : r.azimuth_deg) dirs.push_back(DirOf(r.elevation_deg[e], a));
      const double mu = dirs[0][2];
      for (int shadowed = 0; shadowed < 2; ++shadowed) {
        ViewSegment seg;
        seg.max_altitude_m = o.cut_altitude_m;
        seg.max_distance_m = j + 1 == nx ? kInf : r.depth_x[j] * geo.BoundaryDistanceM(mu);
        seg.single_scattering = shadowed == 0;
        const uint64_t base = kTableStreams + (task * 2 + shadowed) * na;
        std::vector<std::array<double, 4>> out;
        renderer.Render(t.sun_zenith_deg * kDeg, dirs, seg, base, &out);
        for (size_t a = 0; a < na; ++a) {
          const size_t i = r.TableIndex(e, a, j);
          std::vector<float>& dst = shadowed ? t.shadowed_xyz : t.xyz;
          for (int c = 0; c < 3; ++c) dst[i * 3 + c] = static_cast<float>(out[a][c]);
          (shadowed ? t.shadowed_y_stderr : t.y_stderr)[i] = static_cast<float>(out[a][3]);
        }
      }
      const size_t n = ++done;
      if (progress) progress("fog depth tables", static_cast<double>(n) / tasks);
    }
  });

  // ---- Transmittances (spectral; deterministic quadrature): shard 0's.
  r.attenuation_width = o.attenuation_width;
  r.attenuation_height = o.attenuation_height;
  const size_t nodes = static_cast<size_t>(o.attenuation_width) * o.attenuation_height;
  r.depth_transmittance.assign(ne * nx * nw, 0.0f);
  r.attenuation.assign(nodes * nw, 0.0f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, own.small_parts ? ne * nx : 0, 4), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<double> T;
    for (size_t q = range.begin(); q != range.end(); ++q) {
      const size_t e = q / nx, j = q % nx;
      const double mu = std::sin(r.elevation_deg[e] * kDeg);
      SegmentTransmittance(m, h, mu, r.depth_x[j] * geo.BoundaryDistanceM(mu), &T);
      for (size_t w = 0; w < nw; ++w) r.depth_transmittance[q * nw + w] = static_cast<float>(T[w]);
    }
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, own.small_parts ? nodes : 0, 4), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<double> T;
    for (size_t q = range.begin(); q != range.end(); ++q) {
      const double u = static_cast<double>(q % o.attenuation_width) / (o.attenuation_width - 1);
      const double v = static_cast<double>(q / o.attenuation_width) / (o.attenuation_height - 1);
      const double mu = MuOfV(v);
      SegmentTransmittance(m, h, mu, DepthOfU(u) * geo.BoundaryDistanceM(mu), &T);
      for (size_t w = 0; w < nw; ++w) r.attenuation[q * nw + w] = static_cast<float>(T[w]);
    }
  });

  // ---- Observer XYZ -> the CIE-XYZ-D65 reference (as sky-render render writes).
  const ColorConfig config = ColorConfig::Load(scene.ocio_config);
  const ColorProcessor to_reference = config.Converter(XyzColorSpace(scene.observer), ocio_names::kCieXyzD65);
  for (auto& s : r.slice_xyz) to_reference.Apply(s);
  for (auto& s : r.slice_shadowed_xyz) to_reference.Apply(s);
  for (FogDepthTable& t : r.tables) {
    to_reference.Apply(t.xyz);
    to_reference.Apply(t.shadowed_xyz);
  }
  return r;
}

}  // namespace skybake::fog
