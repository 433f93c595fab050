#include "fog/fog_reference.h"

#include <cmath>
#include <numbers>
#include <span>

#include "io/error.h"
#include "spectrum/cmf.h"
#include "spectrum/grid.h"

namespace skybake::fog {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}  // namespace

std::array<double, 3> DirOf(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * kDeg, a = azimuth_deg * kDeg;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

std::array<double, 3> LuminanceRow(const ColorProcessor& to_xyz) {
  std::array<double, 3> row{};
  for (int c = 0; c < 3; ++c) {
    std::array<float, 3> e{0, 0, 0};
    e[c] = 1.0f;
    row[c] = to_xyz.Apply(e)[1];
  }
  return row;
}

double Dot(const std::array<double, 3>& a, const std::array<double, 3>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

FogReference MakeFogReference(const FogRender& render, const FogFitOptions& o, const ColorProcessor& to2020,
                              const std::array<double, 3>& y_row) {
  FogReference ref;
  ref.render = &render;
  ref.options = &o;
  ref.y_row = y_row;
  ref.ne = render.elevation_deg.size();
  ref.na = render.azimuth_deg.size();
  ref.nx = render.depth_x.size();
  ref.n_tab = render.tables.size();
  ref.fog.resize(ref.n_tab);
  ref.shadowed.resize(ref.n_tab);
  for (size_t s = 0; s < ref.n_tab; ++s) {
    ref.fog[s] = render.tables[s].xyz;
    ref.shadowed[s] = render.tables[s].shadowed_xyz;
    to2020.Apply(ref.fog[s]);
    to2020.Apply(ref.shadowed[s]);
  }
  const FogGeometry geo = render.geometry();
  ref.mu.resize(ref.ne);
  ref.theta.resize(ref.ne);
  ref.depth_max.resize(ref.ne);
  for (size_t e = 0; e < ref.ne; ++e) {
    ref.mu[e] = std::sin(render.elevation_deg[e] * kDeg);
    ref.theta[e] = geo.Theta(o.angle, ref.mu[e]);
    ref.depth_max[e] = geo.BoundaryDistanceM(ref.mu[e]);
  }
  return ref;
}

std::array<FitResult, 3> FitOn(const FogReference& ref, const std::vector<std::vector<float>>& data, const SampleFilter& use) {
  const FogRender& render = *ref.render;
  const FogFitOptions& o = *ref.options;
  const size_t n_tab = ref.n_tab, ne = ref.ne, na = ref.na, nx = ref.nx;
  std::array<FitResult, 3> fits;
  const int channels = o.per_channel ? 3 : 1;
  for (int c = 0; c < channels; ++c) {
    std::vector<FitSample> samples;
    samples.reserve(n_tab * ne * na * nx);
    for (size_t s = 0; s < n_tab; ++s) {
      for (size_t e = 0; e < ne; ++e) {
        for (size_t az = 0; az < na; ++az) {
          if (!use(s, az, e)) continue;
          const size_t i1 = render.TableIndex(e, az, nx - 1);
          const double v1 = o.per_channel ? data[s][i1 * 3 + c] : Dot(ref.y_row, {data[s][i1 * 3], data[s][i1 * 3 + 1], data[s][i1 * 3 + 2]});
          for (size_t j = 0; j + 1 < nx; ++j) {
            const size_t i = render.TableIndex(e, az, j);
            const double v = o.per_channel ? data[s][i * 3 + c] : Dot(ref.y_row, {data[s][i * 3], data[s][i * 3 + 1], data[s][i * 3 + 2]});
            samples.push_back({ref.theta[e], render.depth_x[j], v1 > 0.0 ? v / v1 : -1.0});
          }
        }
      }
    }
    const FitResult f = FitDepthFactor(samples, o.fit);
    for (int k = (o.per_channel ? c : 0); k < (o.per_channel ? c + 1 : 3); ++k) fits[static_cast<size_t>(k)] = f;
  }
  return fits;
}

SunlightTransmittance::SunlightTransmittance(const FogRender& render, const ColorConfig& config,
                                             std::vector<std::filesystem::path>* files_read)
    : render_(render), nw_(render.wavelength_nm.size()) {
  const std::optional<Observer> obs = ParseObserver(render.observer);
  if (!obs) throw InputError(FileLoc{render.path, 0}, "unknown observer '" + render.observer + "'");
  const Cmf cmf = Cmf::LoadDefault(*obs);
  if (files_read) files_read->push_back(cmf.path());
  weights_.emplace(WavelengthGrid::List(render.wavelength_nm, FileLoc{render.path, 0}), cmf);
  to2020_ = config.Converter(XyzColorSpace(*obs), ocio_names::kLinearRec2020);
  e0_rgb_ = SunRgb(nullptr);
  for (int c = 0; c < 3; ++c) {
    if (!(e0_rgb_[c] > 0.0f)) throw InputError(FileLoc{render.path, 0}, "the sun's colour has a non-positive Rec.2020 channel");
  }
}

std::array<float, 3> SunlightTransmittance::SunRgb(const float* T) const {
  std::vector<double> spec(nw_);
  for (size_t l = 0; l < nw_; ++l) spec[l] = render_.sun_e0[l] * (T ? T[l] : 1.0);
  const Xyz x = weights_->Integrate(std::span<const double>(spec));
  return to2020_.Apply(std::array<float, 3>{static_cast<float>(x.X), static_cast<float>(x.Y), static_cast<float>(x.Z)});
}

std::array<float, 3> SunlightTransmittance::operator()(const float* T) const {
  const std::array<float, 3> c = SunRgb(T);
  return {c[0] / e0_rgb_[0], c[1] / e0_rgb_[1], c[2] / e0_rgb_[2]};
}

}  // namespace skybake::fog
