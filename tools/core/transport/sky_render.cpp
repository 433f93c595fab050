#include "transport/sky_render.h"

#include "atmosphere/ray_sphere.h"
#include "transport/ambient.h"
#include "transport/sky_shard.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

namespace skybake {

namespace {
constexpr double kPi = std::numbers::pi;
void FillTransmittanceAndSun(const AtmosphereModel& m, const std::vector<std::array<double, 3>>& weights,
                             const SkyRenderSettings& s, SkyRenderResult* result);
}

double TransmittanceToSpace(const AtmosphereModel& m, double altitude_m, double zenith_rad, size_t wl) {
  std::vector<double> t;
  TransmittanceToSpace(m, altitude_m, zenith_rad, &t, wl);
  return t[0];
}

void TransmittanceToSpace(const AtmosphereModel& m, double altitude_m, double zenith_rad, std::vector<double>* out,
                          size_t only_wl) {
  const size_t nw = only_wl == kAllWavelengths ? m.wavelengths() : 1;
  const size_t w0 = only_wl == kAllWavelengths ? 0 : only_wl;
  out->assign(nw, 0.0);
  const double r0 = m.bottom_radius_m + altitude_m;
  const double mu = std::cos(zenith_rad);
  // Ray-sphere geometry from r0 along mu: r(t)^2 = r0^2 + 2 r0 mu t + t^2.
  const double b = r0 * mu, r2 = r0 * r0;
  if (mu < 0.0 && SphereDiscriminantDot(b, r2, m.bottom_radius_m) >= 0.0) {
    const double t_ground = DistanceToSphereInDot(b, r2, m.bottom_radius_m);
    if (t_ground >= 0.0) return;
  }
  const double length = DistanceToSphereOutDot(b, r2, m.top_radius_m);
  // Composite 4-point Gauss-Legendre on pieces of <= 100 m (the profile's level spacing is
  // 100 m by default; the integrand is smooth within a level and the rule is exact to ~1e-7).
  static const double kX[2] = {0.3399810435848563, 0.8611363115940526};
  static const double kW[2] = {0.6521451548625461, 0.3478548451374538};
  const int pieces = std::max(1, static_cast<int>(std::ceil(length / 100.0)));
  const double h = length / pieces;
  // Every wavelength in one walk (the altitude located once per point); each wavelength's sum
  // runs in the same order as alone, so the values do not depend on how many are asked for.
  std::vector<double>& tau = *out;
  std::vector<double> ext(nw);
  for (int p = 0; p < pieces; ++p) {
    const double c = (p + 0.5) * h;
    for (int k = 0; k < 2; ++k) {
      const double wk = kW[k] * 0.5 * h;
      for (double sgn : {-1.0, 1.0}) {
        const double t = c + sgn * 0.5 * h * kX[k];
        const double r = RadiusAt(r0, mu, t);
        const AtmosphereModel::Cell cell = m.Locate(r - m.bottom_radius_m);
        m.Extinction(cell, w0, nw, ext.data());
        for (size_t w = 0; w < nw; ++w) tau[w] += wk * ext[w];
      }
    }
  }
  for (double& v : tau) v = std::exp(-v);
}

SkyRenderResult RenderSky(const PathTracer& tracer, const SkyRenderSettings& s, const ProgressFn& progress) {
  const AtmosphereModel& m = tracer.model();
  SkyRenderResult result;
  const glm::dvec3 observer(0.0, 0.0, m.bottom_radius_m + s.observer_altitude_m);
  const SkyMapping& g = *s.mapping;
  const int W = g.width(), H = g.height();
  const size_t texels = static_cast<size_t>(W) * static_cast<size_t>(H);

  // Texels to compute: one of each mirror pair.
  std::vector<size_t> work;
  std::vector<size_t> mirror(texels);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t t = static_cast<size_t>(y) * W + x;
      const std::array<int, 2> mirrored = g.Mirror(x, y);
      const size_t tm = static_cast<size_t>(mirrored[1]) * W + mirrored[0];
      mirror[t] = tm;
      if (t <= tm) work.push_back(t);
    }
  }

  // The shard's tasks: (slice si, work item k) is task si * work.size() + k (transport/sky_shard.h).
  const uint64_t nwork = work.size();
  const auto [task_begin, task_end] =
      ShardTasks({s.shard_index, s.shard_count}, nwork * static_cast<uint64_t>(s.sun_zenith_deg.size()));
  const size_t total_tasks = static_cast<size_t>(task_end - task_begin);
  std::atomic<size_t> done{0};
  std::atomic<uint64_t> total_paths{0};
  for (size_t si = 0; si < s.sun_zenith_deg.size(); ++si) {
    const uint64_t first = si * nwork;
    const size_t k0 = static_cast<size_t>(std::clamp(task_begin, first, first + nwork) - first);
    const size_t k1 = static_cast<size_t>(std::clamp(task_end, first, first + nwork) - first);
    if (k0 >= k1) continue;  // another shard's slice
    SkySlice slice;
    slice.index = si;
    slice.sun_zenith_deg = s.sun_zenith_deg[si];
    const double theta_s = slice.sun_zenith_deg * kPi / 180.0;
    const glm::dvec3 sun = DirectionFromAngles(theta_s, 0.0);
    slice.xyz.assign(texels * 3, std::numeric_limits<float>::quiet_NaN());
    slice.y_stderr.assign(texels, std::numeric_limits<float>::quiet_NaN());
    slice.paths.assign(texels, 0.0f);
    slice.owned.assign(texels, 0);
    for (size_t k = k0; k < k1; ++k) slice.owned[work[k]] = slice.owned[mirror[work[k]]] = 1;
    tbb::parallel_for(tbb::blocked_range<size_t>(k0, k1, 1), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t k = range.begin(); k != range.end(); ++k) {
        const size_t t = work[k];
        const int x = static_cast<int>(t % static_cast<size_t>(W)), y = static_cast<int>(t / static_cast<size_t>(W));
        std::optional<std::array<double, 3>> d = g.TexelDirection(x, y, theta_s);
        if (d) {
          const glm::dvec3 dir = glm::normalize(glm::dvec3((*d)[0], (*d)[1], (*d)[2]));
          const uint64_t stream = static_cast<uint64_t>(si) * texels + t;
          ColorEstimate e = tracer.Radiance(observer, dir, sun, stream);
          for (size_t tt : {t, mirror[t]}) {
            for (size_t c = 0; c < 3; ++c) slice.xyz[tt * 3 + c] = static_cast<float>(e.xyz[c]);
            slice.y_stderr[tt] = static_cast<float>(e.xyz_stderr[1]);
            slice.paths[tt] = static_cast<float>(e.paths);
          }
          total_paths += e.paths;
        }
        const size_t n = ++done;
        if (progress && (n % 64 == 0 || n == total_tasks)) progress("sky radiance", static_cast<double>(n) / total_tasks);
      }
    });
    if (s.ambient && k0 == 0) {  // the slice's ambient belongs to the shard of its texel 0
      const uint64_t stream = (uint64_t{1} << 40) + si;
      slice.ambient = tracer.Irradiance(observer, sun, stream);
      total_paths += slice.ambient.paths;
    }
    result.slices.push_back(std::move(slice));
  }
  result.total_paths = total_paths;
  // Transmittance table and direct sun at the observer (disk centre transmittance).
  FillTransmittanceAndSun(m, tracer.xyz_weights(), s, &result);
  return result;
}

namespace {

// Transmittance table and direct sun, shared by both renderers.
void FillTransmittanceAndSun(const AtmosphereModel& m, const std::vector<std::array<double, 3>>& weights,
                             const SkyRenderSettings& s, SkyRenderResult* result) {
  const size_t nw = m.wavelengths();
  // In parallel over the angles and slices (each value is computed alone, so the bytes do not
  // depend on the thread count): serially, these 245 x nw ray integrals were a tenth of a
  // clear-sky LUT on one thread and what held the 1 -> 2 thread scaling at 1.75x.
  const size_t na = static_cast<size_t>(std::max(0, s.transmittance_angles));
  result->transmittance_zenith_deg.resize(na);
  result->transmittance.resize(na * nw);
  for (SkySlice& slice : result->slices) slice.sun_irradiance.assign(nw, 0.0);
  tbb::parallel_for(size_t{0}, na + result->slices.size(), [&](size_t i) {
    if (i < na) {
      const double zen = 180.0 * static_cast<double>(i) / std::max(1, s.transmittance_angles - 1);
      result->transmittance_zenith_deg[i] = zen;
      std::vector<double> t;
      TransmittanceToSpace(m, s.observer_altitude_m, zen * kPi / 180.0, &t);
      std::copy(t.begin(), t.end(), result->transmittance.begin() + static_cast<std::ptrdiff_t>(i * nw));
    } else {
      SkySlice& slice = result->slices[i - na];
      const double theta_s = slice.sun_zenith_deg * kPi / 180.0;
      std::vector<double> t;
      TransmittanceToSpace(m, s.observer_altitude_m, theta_s, &t);
      for (size_t w = 0; w < nw; ++w) slice.sun_irradiance[w] = m.sun.irradiance[w] * t[w];
    }
  });
  for (SkySlice& slice : result->slices) {
    slice.sun_xyz = {0, 0, 0};
    for (size_t w = 0; w < nw; ++w) {
      for (size_t c = 0; c < 3; ++c) slice.sun_xyz[c] += weights[w][c] * slice.sun_irradiance[w];
    }
  }
}

}  // namespace

SkyRenderResult RenderSkyDeterministic(const SkyMethod& method, const AtmosphereModel& m,
                                       const std::vector<std::array<double, 3>>& weights, const SkyRenderSettings& s,
                                       const ProgressFn& progress) {
  const size_t nw = m.wavelengths();
  const SkyMapping& g = *s.mapping;
  const int W = g.width(), H = g.height();
  const size_t texels = static_cast<size_t>(W) * H;
  SkyRenderResult result;
  std::atomic<size_t> done{0};
  // One task per slice (transport/sky_shard.h).
  const auto [slice_begin, slice_end] = ShardTasks({s.shard_index, s.shard_count}, s.sun_zenith_deg.size());
  const size_t total = static_cast<size_t>(slice_end - slice_begin) * static_cast<size_t>(H);
  for (size_t si = static_cast<size_t>(slice_begin); si < static_cast<size_t>(slice_end); ++si) {
    const double sza = s.sun_zenith_deg[si];
    SkySlice slice;
    slice.index = si;
    slice.sun_zenith_deg = sza;
    slice.owned.assign(texels, 1);
    const double theta_s = sza * kPi / 180.0;
    slice.xyz.assign(texels * 3, std::numeric_limits<float>::quiet_NaN());
    slice.y_stderr.assign(texels, 0.0f);
    slice.paths.assign(texels, 0.0f);
    if (s.ambient) {
      // transport/ambient.h: the hemisphere's grid and a cap around the sun. Before the texels,
      // so that a method keeping view rays between calls (orders) keeps the grid's 16 rings,
      // which recur in every slice (the same values either way).
      const std::vector<double> E = AmbientIrradiance(method, s.observer_altitude_m, theta_s);
      for (size_t w = 0; w < nw; ++w) {
        for (size_t c = 0; c < 3; ++c) slice.ambient.xyz[c] += weights[w][c] * E[w];
      }
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, H, 1), [&](const tbb::blocked_range<int>& rows) {
      for (int y = rows.begin(); y != rows.end(); ++y) {
        std::vector<std::array<double, 3>> dirs;
        std::vector<size_t> at;
        for (int x = 0; x < W; ++x) {
          const size_t t = static_cast<size_t>(y) * W + x;
          const std::array<int, 2> mirrored = g.Mirror(x, y);
          const size_t tm = static_cast<size_t>(mirrored[1]) * W + mirrored[0];
          if (tm < t) continue;  // computed with its mirror
          std::optional<std::array<double, 3>> d = g.TexelDirection(x, y, theta_s);
          if (!d) continue;
          dirs.push_back(*d);
          at.push_back(t);
        }
        std::vector<double> L;
        if (!dirs.empty()) method.Radiance(s.observer_altitude_m, theta_s, dirs, &L);
        for (size_t k = 0; k < at.size(); ++k) {
          std::array<double, 3> xyz{0, 0, 0};
          for (size_t w = 0; w < nw; ++w) {
            for (size_t c = 0; c < 3; ++c) xyz[c] += weights[w][c] * L[k * nw + w];
          }
          const int x = static_cast<int>(at[k] % static_cast<size_t>(W)), yy = static_cast<int>(at[k] / static_cast<size_t>(W));
          const std::array<int, 2> mirrored = g.Mirror(x, yy);
          for (size_t tt : {at[k], static_cast<size_t>(mirrored[1]) * W + mirrored[0]}) {
            for (size_t c = 0; c < 3; ++c) slice.xyz[tt * 3 + c] = static_cast<float>(xyz[c]);
          }
        }
        const size_t n = ++done;
        if (progress) progress("sky radiance", static_cast<double>(n) / total);
      }
    });
    result.slices.push_back(std::move(slice));
  }
  FillTransmittanceAndSun(m, weights, s, &result);
  return result;
}

}  // namespace skybake
