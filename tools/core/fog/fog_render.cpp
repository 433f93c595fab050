#include "fog/fog_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "color/color.h"
#include "fog/fog_evaluator.h"
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

std::string TablePartName(double sza) { return fmt::format("depth.sza_{:06.2f}", sza); }
std::string SlicePartName(size_t k, double sza) { return fmt::format("fog.slice_{:02d}.sza_{:06.2f}", k, sza); }

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
    if (!names.insert(TablePartName(z)).second) throw UsageError(fmt::format("--sun-zenith-deg: {} is listed twice", z));
  }

  FogRender r;
  r.atmosphere = scene.spec.name;
  r.method = o.method;
  r.observer = ObserverName(scene.observer);
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
  std::atomic<size_t> done{0};
  const size_t slice_rows = n_slices * static_cast<size_t>(r.lut_height);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, slice_rows, 1), [&](const tbb::blocked_range<size_t>& range) {
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
  const size_t tasks = r.tables.size() * ne * nx;
  done = 0;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tasks, 1), [&](const tbb::blocked_range<size_t>& range) {
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

  // ---- Transmittances (spectral; deterministic quadrature).
  r.depth_transmittance.assign(ne * nx * nw, 0.0f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ne * nx, 4), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<double> T;
    for (size_t q = range.begin(); q != range.end(); ++q) {
      const size_t e = q / nx, j = q % nx;
      const double mu = std::sin(r.elevation_deg[e] * kDeg);
      SegmentTransmittance(m, h, mu, r.depth_x[j] * geo.BoundaryDistanceM(mu), &T);
      for (size_t w = 0; w < nw; ++w) r.depth_transmittance[q * nw + w] = static_cast<float>(T[w]);
    }
  });
  r.attenuation_width = o.attenuation_width;
  r.attenuation_height = o.attenuation_height;
  const size_t nodes = static_cast<size_t>(o.attenuation_width) * o.attenuation_height;
  r.attenuation.assign(nodes * nw, 0.0f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes, 4), [&](const tbb::blocked_range<size_t>& range) {
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

// ------------------------------------------------------------------------------------- writing

namespace {

void SetFogAttributes(ExrImage& img, const FogRender& r) {
  img.strings["skybake.fog.atmosphere"] = r.atmosphere;
  img.strings["skybake.fog.method"] = r.method;
  img.strings["skybake.observer"] = r.observer;
  img.doubles["skybake.fog.planet_radius_m"] = r.planet_radius_m;
  img.doubles["skybake.fog.top_altitude_m"] = r.top_altitude_m;
  img.doubles["skybake.fog.observer_altitude_m"] = r.observer_altitude_m;
  img.doubles["skybake.fog.cut_altitude_m"] = r.cut_altitude_m;
}

std::string Segment(const FogRender& r) {
  return fmt::format("the medium on the view ray below {} m of altitude (the cut) and, in depth tables, closer than "
                     "the depth; lit by the full atmosphere; no ground surface (transport/view_segment.h)",
                     FormatExact(r.cut_altitude_m));
}

}  // namespace

void WriteFogRender(const Scene& scene, const FogRenderOptions& o, const FogRender& r, const fs::path& path,
                    const std::string& tool) {
  Provenance prov;
  prov.tool = tool;
  std::string az, sz;
  for (double a : r.azimuth_deg) az += (az.empty() ? "" : ",") + FormatExact(a);
  for (const FogDepthTable& t : r.tables) sz += (sz.empty() ? "" : ",") + FormatExact(t.sun_zenith_deg);
  prov.parameters = fmt::format(
      "subcommand: fog\ncut_altitude_m: {}\nobserver_altitude_m: {}\nlut_size: {}x{}\nlut_texels: {}\ntime_mapping: {}\n"
      "sun_zenith_deg: [{}]\nelevations: {}\nazimuth_deg: [{}]\ndepths: {}\nattenuation_size: {}x{}\n",
      FormatExact(r.cut_altitude_m), FormatExact(r.observer_altitude_m), r.lut_width, r.lut_height,
      gt7::TexelGridName(r.texel_grid), r.time_mapping_name, sz, r.elevation_deg.size(), az, r.depth_x.size(), r.attenuation_width, r.attenuation_height) +
                    r.method_description + scene.parameters;
  for (const fs::path& f : scene.files_read) prov.AddInput(f);
  (void)o;

  std::vector<ExrPart> parts;
  const gt7::Gt7SkyMapping mapping = r.mapping();
  const size_t texels = static_cast<size_t>(r.lut_width) * r.lut_height;
  for (size_t k = 0; k < r.slice_zenith_deg.size(); ++k) {
    ExrImage img;
    img.Resize(r.lut_width, r.lut_height, {"R", "G", "B", "shadowed_R", "shadowed_G", "shadowed_B", "Y_stderr"});
    for (size_t t = 0; t < texels; ++t) {
      for (int c = 0; c < 3; ++c) {
        img.pixels[t * 7 + c] = r.slice_xyz[k][t * 3 + c];
        img.pixels[t * 7 + 3 + c] = r.slice_shadowed_xyz[k][t * 3 + c];
      }
      img.pixels[t * 7 + 6] = r.slice_y_stderr[k][t];
    }
    img.chromaticities = XyzChromaticities();
    img.strings["skybake.quantity"] =
        "fog of the whole low-atmosphere segment (normalised depth x = 1): in-scattered radiance, R, G, B = X, Y, Z "
        "(cd/m^2, CIE-XYZ-D65); shadowed_*: the same without the single-scattered sun; Y_stderr: the fog's standard "
        "error (path). Directions below the horizon are clamped to it. Segment: " + Segment(r);
    img.strings["skybake.mapping"] = mapping.Describe();
    img.doubles["skybake.sun_zenith_deg"] = r.slice_zenith_deg[k];
    img.doubles["skybake.observer_altitude_m"] = r.observer_altitude_m;
    img.strings["skybake.time_mapping"] = r.time_mapping_name;
    img.strings["skybake.time_mapping.description"] = r.time.Describe();
    img.doubles["skybake.time_mapping.observer_radius_m"] = r.time.observer_radius_m;
    img.doubles["skybake.time_mapping.top_radius_m"] = r.time.top_radius_m;
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({SlicePartName(k, r.slice_zenith_deg[k]), std::move(img)});
  }
  const ExrAxis depth_axis{"depth_x", "1", "normalised depth x = d / D: (j/n)^3, j = 1..n (D: distance to the cut sphere)",
                           r.depth_x};
  const ExrAxis elevation_axis{"elevation", "deg", "view elevation above the horizon: 90 (i/(m-1))^2", r.elevation_deg};
  for (const FogDepthTable& t : r.tables) {
    ExrTable tab;
    tab.axes = {depth_axis, {"azimuth", "deg", "view azimuth from the sun (0: towards the sun's azimuth)", r.azimuth_deg},
                elevation_axis};
    tab.channels = {"X", "Y", "Z", "shadowed_X", "shadowed_Y", "shadowed_Z", "Y_stderr", "shadowed_Y_stderr"};
    tab.channel_units = {"cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2", "cd/m^2"};
    const size_t n = t.y_stderr.size();
    tab.values.reserve(n * 8);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) tab.values.push_back(t.xyz[i * 3 + c]);
      for (int c = 0; c < 3; ++c) tab.values.push_back(t.shadowed_xyz[i * 3 + c]);
      tab.values.push_back(t.y_stderr[i]);
      tab.values.push_back(t.shadowed_y_stderr[i]);
    }
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] =
        "fog between the observer and depth x D: in-scattered radiance X, Y, Z (cd/m^2, CIE-XYZ-D65); shadowed_*: "
        "without the single-scattered sun. Segment: " + Segment(r);
    img.doubles["skybake.sun_zenith_deg"] = t.sun_zenith_deg;
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({TablePartName(t.sun_zenith_deg), std::move(img)});
  }
  const ExrAxis wl_axis{"wavelength", "nm", "the model's wavelength grid", r.wavelength_nm};
  {
    ExrTable tab;
    tab.axes = {wl_axis, depth_axis, elevation_axis};
    tab.channels = {"transmittance"};
    tab.channel_units = {"1"};
    tab.values = r.depth_transmittance;
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] = "transmittance from the observer to depth x D along the elevation";
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({"depth_transmittance", std::move(img)});
  }
  {
    std::vector<double> u, v;
    for (int i = 0; i < r.attenuation_width; ++i) u.push_back(static_cast<double>(i) / (r.attenuation_width - 1));
    for (int i = 0; i < r.attenuation_height; ++i) v.push_back(static_cast<double>(i) / (r.attenuation_height - 1));
    ExrTable tab;
    tab.axes = {wl_axis, {"u", "1", "attenuation LUT node u = x^(1/3) (x: normalised depth)", u},
                {"v", "1", "attenuation LUT node v = (elevation / 90 deg)^(1/2)", v}};
    tab.channels = {"transmittance"};
    tab.channel_units = {"1"};
    tab.values = r.attenuation;
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] = "transmittance from the observer to depth x D at the attenuation LUT's nodes";
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({"attenuation", std::move(img)});
  }
  {
    ExrTable tab;
    tab.axes = {wl_axis};
    tab.channels = {"e0"};
    tab.channel_units = {"W m^-2 nm^-1"};
    for (double e : r.sun_e0) tab.values.push_back(static_cast<float>(e));
    ExrImage img = TableToImage(tab);
    img.strings["skybake.quantity"] = "extraterrestrial solar spectral irradiance on the grid (the model's sun)";
    SetFogAttributes(img, r);
    SetProvenance(img, prov);
    parts.push_back({"sun", std::move(img)});
  }
  WriteExrParts(path, parts);
}

// ------------------------------------------------------------------------------------- reading

namespace {

const std::string* StringAttr(const ExrImage& img, const std::string& key) {
  auto it = img.strings.find(key);
  return it == img.strings.end() ? nullptr : &it->second;
}
const double* DoubleAttr(const ExrImage& img, const std::string& key) {
  auto it = img.doubles.find(key);
  return it == img.doubles.end() ? nullptr : &it->second;
}

// The index NN of "fog.slice_NN.sza_...", or -1.
int SliceIndex(const std::string& name) {
  const std::string prefix = "fog.slice_";
  if (name.rfind(prefix, 0) != 0) return -1;
  int i = -1;
  const char* b = name.data() + prefix.size();
  const char* e = name.data() + name.size();
  auto res = std::from_chars(b, e, i);
  if (res.ec != std::errc() || res.ptr == b || res.ptr == e || *res.ptr != '.') return -1;
  return i;
}

}  // namespace

FogRender ReadFogRender(const fs::path& path) {
  const std::string name = path.string();
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, msg); };
  const std::vector<ExrPart> parts = ReadExrParts(path);
  FogRender r;
  r.path = name;
  const ExrImage& sun_img = FindPart(parts, "sun", name);
  auto need_d = [&](const ExrImage& img, const std::string& part, const std::string& key) {
    const double* v = DoubleAttr(img, key);
    if (!v || !std::isfinite(*v)) fail("part '" + part + "' has no " + key + ": not a sky-render fog render");
    return *v;
  };
  auto need_s = [&](const ExrImage& img, const std::string& part, const std::string& key) {
    const std::string* v = StringAttr(img, key);
    if (!v) fail("part '" + part + "' has no " + key + ": not a sky-render fog render");
    return *v;
  };
  r.atmosphere = need_s(sun_img, "sun", "skybake.fog.atmosphere");
  r.method = need_s(sun_img, "sun", "skybake.fog.method");
  r.observer = need_s(sun_img, "sun", "skybake.observer");
  r.planet_radius_m = need_d(sun_img, "sun", "skybake.fog.planet_radius_m");
  r.top_altitude_m = need_d(sun_img, "sun", "skybake.fog.top_altitude_m");
  r.observer_altitude_m = need_d(sun_img, "sun", "skybake.fog.observer_altitude_m");
  r.cut_altitude_m = need_d(sun_img, "sun", "skybake.fog.cut_altitude_m");
  try {
    (void)r.geometry();
  } catch (const UsageError& e) {
    fail(e.what());
  }
  if (const std::string* p = StringAttr(sun_img, "skybake.parameters")) {
    const size_t at = p->find("method: ");
    if (at != std::string::npos) r.method_description = p->substr(at, p->find('\n', at) - at);
  }
  {
    const ExrTable t = ImageToTable(sun_img, name);
    if (t.axes.size() != 1 || t.axes[0].name != "wavelength" || t.ChannelIndex("e0") < 0) fail("part 'sun' is not a wavelength table of e0");
    r.wavelength_nm = t.axes[0].values;
    for (size_t i = 0; i < t.Count(); ++i) r.sun_e0.push_back(t.At(i, static_cast<size_t>(t.ChannelIndex("e0"))));
  }
  const size_t nw = r.wavelength_nm.size();
  auto same_fog = [&](const ExrImage& img, const std::string& part) {
    for (const char* key : {"skybake.fog.planet_radius_m", "skybake.fog.observer_altitude_m", "skybake.fog.cut_altitude_m"}) {
      const double* v = DoubleAttr(img, key);
      if (!v || *v != *DoubleAttr(sun_img, key)) fail("part '" + part + "' has another " + std::string(key) + " than part 'sun'");
    }
  };
  auto finite = [&](const std::vector<float>& v, const std::string& part) {
    for (float x : v) {
      if (!std::isfinite(x)) fail("part '" + part + "' has a value that is not finite");
    }
  };

  // Slices.
  std::vector<const ExrPart*> slices;
  for (const ExrPart& p : parts) {
    if (p.name.rfind("fog.", 0) != 0) continue;
    const int index = SliceIndex(p.name);
    if (index != static_cast<int>(slices.size())) fail(fmt::format("part '{}' is out of order (expected slice {})", p.name, slices.size()));
    slices.push_back(&p);
  }
  if (slices.size() < 4) fail(fmt::format("{} fog LUT slices; a GT7 time mapping has at least 4", slices.size()));
  const ExrImage& first = slices[0]->image;
  r.lut_width = first.width;
  r.lut_height = first.height;
  r.time_mapping_name = need_s(first, slices[0]->name, "skybake.time_mapping");
  const std::optional<gt7::TimeMappingKind> kind = gt7::TimeMapping::ParseName(r.time_mapping_name);
  if (!kind) fail("unknown time mapping '" + r.time_mapping_name + "'");
  r.time.observer_radius_m = need_d(first, slices[0]->name, "skybake.time_mapping.observer_radius_m");
  r.time.top_radius_m = need_d(first, slices[0]->name, "skybake.time_mapping.top_radius_m");
  r.time.upper_slices = kind->upper;
  r.time.lower_slices = kind->lower;
  r.time.upper_power = kind->upper_power;
  if (!(r.time.observer_radius_m > 0.0 && r.time.top_radius_m > r.time.observer_radius_m)) fail("bad time mapping radii");
  if (static_cast<int>(slices.size()) != r.time.slices()) {
    fail(fmt::format("{} fog LUT slices, but the time mapping '{}' has {}", slices.size(), r.time_mapping_name, r.time.slices()));
  }
  // The texel grid (centres or nodes) is part of the mapping's description: read it from there.
  const std::string* first_mapping = StringAttr(first, "skybake.mapping");
  for (gt7::TexelGrid g : {gt7::TexelGrid::kCentres, gt7::TexelGrid::kNodes}) {
    if (first_mapping && *first_mapping == gt7::Gt7SkyMapping(r.lut_width, r.lut_height, r.sphere, g).Describe()) r.texel_grid = g;
  }
  const std::string expect_mapping = r.mapping().Describe();
  const std::vector<double> expect_zenith = r.time.SliceZenithDeg();
  const size_t texels = static_cast<size_t>(r.lut_width) * r.lut_height;
  for (size_t k = 0; k < slices.size(); ++k) {
    const ExrImage& img = slices[k]->image;
    const std::string& pn = slices[k]->name;
    if (img.width != r.lut_width || img.height != r.lut_height) fail("part '" + pn + "' has another size than the first slice");
    const std::string* mp = StringAttr(img, "skybake.mapping");
    if (!mp || *mp != expect_mapping) fail("part '" + pn + "' is not on the GT7 sphere mapping");
    const double sza = need_d(img, pn, "skybake.sun_zenith_deg");
    if (std::fabs(sza - expect_zenith[k]) > 1e-9) {
      fail(fmt::format("part '{}': sun zenith {} deg, but slice {} of the time mapping is at {} deg", pn, FormatExact(sza), k,
                       FormatExact(expect_zenith[k])));
    }
    same_fog(img, pn);
    r.slice_zenith_deg.push_back(sza);
    int ci[7];
    const char* ch[7] = {"R", "G", "B", "shadowed_R", "shadowed_G", "shadowed_B", "Y_stderr"};
    for (int c = 0; c < 7; ++c) {
      ci[c] = img.ChannelIndex(ch[c]);
      if (ci[c] < 0) fail("part '" + pn + "' lacks the channel " + std::string(ch[c]));
    }
    std::vector<float> xyz(texels * 3), sh(texels * 3), se(texels);
    const size_t nc = img.channels.size();
    for (size_t t = 0; t < texels; ++t) {
      for (int c = 0; c < 3; ++c) {
        xyz[t * 3 + c] = img.pixels[t * nc + ci[c]];
        sh[t * 3 + c] = img.pixels[t * nc + ci[3 + c]];
      }
      se[t] = img.pixels[t * nc + ci[6]];
    }
    finite(xyz, pn);
    finite(sh, pn);
    r.slice_xyz.push_back(std::move(xyz));
    r.slice_shadowed_xyz.push_back(std::move(sh));
    r.slice_y_stderr.push_back(std::move(se));
  }

  // Depth tables.
  for (const ExrPart& p : parts) {
    if (p.name.rfind("depth.", 0) != 0) continue;
    const ExrTable t = ImageToTable(p.image, name);
    if (t.axes.size() != 3 || t.axes[0].name != "depth_x" || t.axes[1].name != "azimuth" || t.axes[2].name != "elevation") {
      fail("part '" + p.name + "' is not a depth_x x azimuth x elevation table");
    }
    same_fog(p.image, p.name);
    if (r.tables.empty()) {
      r.depth_x = t.axes[0].values;
      r.azimuth_deg = t.axes[1].values;
      r.elevation_deg = t.axes[2].values;
    } else if (t.axes[0].values != r.depth_x || t.axes[1].values != r.azimuth_deg || t.axes[2].values != r.elevation_deg) {
      fail("part '" + p.name + "' has other axes than the first depth table");
    }
    for (size_t j = 0; j < r.depth_x.size(); ++j) {
      if (!(r.depth_x[j] > 0.0 && r.depth_x[j] <= 1.0) || (j > 0 && !(r.depth_x[j] > r.depth_x[j - 1]))) {
        fail("part '" + p.name + "': depth_x must increase within (0, 1]");
      }
    }
    for (double e : r.elevation_deg) {
      if (!(e >= 0.0 && e <= 90.0)) fail("part '" + p.name + "': elevations must lie in 0-90 deg");
    }
    FogDepthTable d;
    d.sun_zenith_deg = need_d(p.image, p.name, "skybake.sun_zenith_deg");
    int ci[8];
    const char* ch[8] = {"X", "Y", "Z", "shadowed_X", "shadowed_Y", "shadowed_Z", "Y_stderr", "shadowed_Y_stderr"};
    for (int c = 0; c < 8; ++c) {
      ci[c] = t.ChannelIndex(ch[c]);
      if (ci[c] < 0) fail("part '" + p.name + "' lacks the channel " + std::string(ch[c]));
    }
    for (size_t i = 0; i < t.Count(); ++i) {
      for (int c = 0; c < 3; ++c) {
        d.xyz.push_back(t.At(i, ci[c]));
        d.shadowed_xyz.push_back(t.At(i, ci[3 + c]));
      }
      d.y_stderr.push_back(t.At(i, ci[6]));
      d.shadowed_y_stderr.push_back(t.At(i, ci[7]));
    }
    finite(d.xyz, p.name);
    finite(d.shadowed_xyz, p.name);
    r.tables.push_back(std::move(d));
  }
  if (r.tables.empty()) fail("no depth tables (parts depth.sza_*): render with sky-render fog");

  {
    const ExrTable t = ImageToTable(FindPart(parts, "depth_transmittance", name), name);
    if (t.axes.size() != 3 || t.axes[0].values != r.wavelength_nm || t.axes[1].values != r.depth_x ||
        t.axes[2].values != r.elevation_deg || t.channels.size() != 1) {
      fail("part 'depth_transmittance' is not a wavelength x depth_x x elevation table on the depth tables' axes");
    }
    r.depth_transmittance = t.values;
    finite(r.depth_transmittance, "depth_transmittance");
  }
  {
    const ExrTable t = ImageToTable(FindPart(parts, "attenuation", name), name);
    if (t.axes.size() != 3 || t.axes[0].values != r.wavelength_nm || t.axes[1].name != "u" || t.axes[2].name != "v" ||
        t.channels.size() != 1 || t.axes[1].values.size() < 2 || t.axes[2].values.size() < 2) {
      fail("part 'attenuation' is not a wavelength x u x v table");
    }
    r.attenuation_width = static_cast<int>(t.axes[1].values.size());
    r.attenuation_height = static_cast<int>(t.axes[2].values.size());
    r.attenuation = t.values;
    finite(r.attenuation, "attenuation");
  }
  (void)nw;
  return r;
}

}  // namespace skybake::fog
