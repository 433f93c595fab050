// The reference renderer: a spectral Monte-Carlo path tracer for the layered spherical
// atmosphere (GT7 "skysim" class; GT7 sky talk, "Skysim": full-spectrum
// path tracing, ratio tracking, importance sampling).
//
// Estimator (docs/sky-render.md has the derivation):
//  - Wavelengths. Each path carries K wavelengths of the render grid (N samples): a uniformly
//    random "hero" index h and h + floor(j N / K) mod N, j < K (hero wavelength sampling, Wilkie
//    et al. 2014). Each grid index appears with probability K/N, so
//    XYZ ~ (N/K) sum_j w(lambda_j) L(lambda_j) is an unbiased estimate of the grid sum
//    sum_i w_i L_i, where w_i are the colour-matching weights (spectrum/xyz.h).
//  - Free flights: spectral tracking (Kutz, Habel, Li & Novak 2017, "Spectral and decomposition
//    tracking for rendering heterogeneous volumes", §4) with a majorant per spherical shell,
//    mu_bar = max over the shell's levels and the path's wavelengths of the extinction (exact,
//    since coefficients are linear between levels). At a tentative collision the path scatters
//    with probability P_s = avg_j |b_j mu_s,j| / (avg_j |b_j mu_s,j| + avg_j |b_j mu_n,j|) and
//    the throughputs b_j are multiplied by mu_s,j / (mu_bar P_s) (scatter) or mu_n,j /
//    (mu_bar (1 - P_s)) (null); absorption only lowers the weights (no absorption events).
//    Unbiased for any positive probabilities.
//  - Scattering: the next direction is sampled from the mixture of the components' phase
//    functions at the hero wavelength with component probabilities proportional to
//    sum_j b_j mu_s,c(lambda_j); each wavelength is weighted by its own mixture phase / pdf.
//    At a vertex in the Earth's shadow, half of the directions come from a band towards the
//    sun's azimuth instead (twilight_guide, one-sample MIS).
//  - Sun: next-event estimation along every path segment (segment_nee: a point of the sunlit
//    part drawn from a log-linear density that follows scattering x attenuation, towards the
//    sun too with sun_guided_nee) and at every ground vertex, with a direction drawn
//    uniformly in the solar disk's cone (limb darkening in the radiance), transmittance by
//    ratio tracking (Cramer 1978; Novak et al. 2014) with the shell majorants (scaled up where
//    a depth of several is expected), zero when the shadow ray hits the planet (Earth's
//    shadow); or, with segment_nee off, at every scattering vertex. Paths that leave the atmosphere collect
//    nothing in sun mode (so the sun is never counted twice); the sun disk itself is not part
//    of the sky radiance (it is the separate direct-sun output).
//  - Uniform illumination (white-furnace mode): paths that leave the atmosphere collect a
//    constant radiance 1 W m^-2 sr^-1 nm^-1; no next-event estimation.
//  - Ground: Lambertian with spectral albedo; NEE to the sun, then a cosine-weighted bounce
//    (throughput x albedo).
//  - All orders: Russian roulette after `russian_roulette_depth` vertices with survival
//    probability min(1, max_j b_j), weights divided by it (unbiased).
// Randomness: one PCG32 stream per (seed, stream id, path index): results do not depend on
// threads or scheduling.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include <glm/vec3.hpp>

#include "atmosphere/model.h"
#include "transport/random.h"
#include "transport/sun_depth_table.h"

namespace skybake {

enum class Illumination { kSun, kUniform };

struct PathTracerSettings {
  Illumination illumination = Illumination::kSun;
  int wavelengths_per_path = 4;
  // Adaptive sampling stops when stderr(Y) <= target * mean(Y) (and at least min_paths).
  double target_relative_error = 0.01;
  // ... or when stderr(Y) <= this absolute floor (cd/m^2 for radiance, lux for irradiance): a
  // texel darker than the floor need not be resolved relatively. 1e-5 cd/m^2 is ~100x below the
  // natural night-sky luminance (~1e-3 cd/m^2).
  double absolute_error_floor = 1e-5;
  // ... and only once the standard error is itself known to this relative uncertainty (the
  // sample kurtosis gives it: transport/running_moments.h). Under a strongly forward-scattering
  // cloud the samples are heavy-tailed, the sample variance of a few thousand paths understates
  // the true one, and a stop on it alone accepts estimates that are low by several of their
  // claimed errors (docs/sky-render.md "Honest error bars"). 0 = no such condition.
  double stderr_reliability = 0.1;
  // ... and not before the paths in which the sharpest phase peak is expected this many times:
  // a sample variance cannot show a tail it has not sampled. A path's next-event connection
  // falls inside a peak of height P_max (sr^-1), whose solid angle is about 1 / P_max, about
  // once in 4 pi P_max scattering events, so the stop waits for rare_peak_events x 4 pi P_max
  // paths (P_max over the scattering components and wavelengths: 0.12 for air, 11 for the
  // continental aerosol, ~10^3 - 10^4 for cloud droplets). 3 events: a chance of e^-3 = 5 % that
  // none is seen. 0 = no such minimum.
  double rare_peak_events = 3.0;
  uint64_t min_paths = 64;
  uint64_t max_paths = uint64_t{1} << 20;
  uint64_t batch_paths = 64;
  int russian_roulette_depth = 4;
  uint64_t seed = 1;
  // Sun estimator. true: along every path segment, one point is drawn in the part of the
  // segment that the sun can reach (a geometric test against the planet, widened by the disk's
  // penumbra), with a density following the hero wavelength's scattering x attenuation, and
  // the sun is connected from there ("segment NEE"); collisions then do no sun NEE. Unbiased,
  // and it keeps twilight (where most of the medium is in the Earth's shadow) tractable.
  // false: sun NEE at every collision only (the textbook estimator; kept to cross-check).
  bool segment_nee = true;
  // Segment NEE's density also follows the sun's attenuation: each piece's weight is multiplied
  // by exp(-tau) to the sun from a tabulated optical depth (transport/sun_depth_table.h). In
  // twilight most of the geometrically sunlit air sees the sun only through the lower
  // atmosphere's long grazing path; the plain density spends its points there
  // (docs/sky-render.md "Deep twilight"). false: the density follows scattering x view
  // attenuation only.
  bool sun_guided_nee = true;
  // At a scattering vertex in the Earth's shadow, the next direction is drawn half of the time
  // from the phase function and half of the time uniformly in a band about the horizontal
  // direction towards the sun's azimuth (elevation asin(-0.1) to asin(0.35), azimuth within
  // 60 deg: 0.94 sr), weighted by phase / the mixture's density (one-sample MIS, Veach 1997,
  // §9.2.4). From the shadowed lower atmosphere of deep twilight that band is where the sunlit
  // air is seen; the phase function points there rarely (docs/sky-render.md "Deep twilight").
  // Only shadowed vertices use it: the choice depends on the vertex alone, so the estimator is
  // unbiased. false: the phase function alone.
  bool twilight_guide = true;
  // Highest scattering order counted (ground reflections count as orders); 0 = all orders.
  int max_order = 0;
  // Wavelength-sampling decisions (the segment-NEE point, the phase-function direction).
  // false: they follow the path's first wavelength idx[0] (the hero), and every other carried
  // wavelength is weighted by f(lambda_j) / p(lambda_0): unbiased, but where p(lambda_0) is small
  // and f(lambda_j) is not (a 680 nm point far along a ray whose 440 nm attenuation is strong) the
  // weights have a heavy tail, and the sample variance of a modest number of paths
  // underestimates the true one. true: one-sample multiple importance sampling over the carried
  // wavelengths (Veach 1997, §9.2.4, the balance heuristic): each decision draws its technique
  // h uniformly among the k wavelengths, samples from p(lambda_h), and divides every wavelength's
  // contribution by the mixture (1/k) sum_h p(lambda_h); each weight is then bounded by k times
  // the single-wavelength one, so every carried wavelength gets an honest error bar (sky-render
  // points; tests/transport/points_test.cpp measures the coverage).
  bool wavelength_mis = false;
};

// Mean and standard error of an estimated colour (XYZ: cd/m^2 for radiance, lux for irradiance).
struct ColorEstimate {
  std::array<double, 3> xyz{0, 0, 0};
  std::array<double, 3> xyz_stderr{0, 0, 0};
  uint64_t paths = 0;
};

class PathTracer {
 public:
  // `xyz_weights[i]` are the colour-matching weights of grid wavelength i (e.g. 683 x̄ Δλ, ...).
  PathTracer(const AtmosphereModel& model, std::vector<std::array<double, 3>> xyz_weights,
             PathTracerSettings settings);

  const AtmosphereModel& model() const { return model_; }
  const PathTracerSettings& settings() const { return settings_; }
  // Paths an adaptive estimate takes at least (min_paths, or more for a sharp phase peak).
  uint64_t MinPaths() const { return std::max(settings_.min_paths, peak_min_paths_); }
  const std::vector<std::array<double, 3>>& xyz_weights() const { return xyz_weights_; }

  // Sky radiance (XYZ) at `position` (m, planet-centred) looking along `direction` (unit), with
  // the sun centre along `sun_direction` (unit). Adaptive to the target error.
  ColorEstimate Radiance(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction,
                         uint64_t stream) const;
  // In-scattered radiance from the view segment [0, t_end] only (transport/view_segment.h:
  // t_end from SegmentEnd; the ground surface is excluded). single_scattering = false leaves
  // out the order-1 sun connections (shadowed fog). Adaptive.
  ColorEstimate SegmentRadiance(const glm::dvec3& position, const glm::dvec3& direction,
                                const glm::dvec3& sun_direction, double t_end, uint64_t stream,
                                bool single_scattering = true) const;
  // Irradiance from the sky on a horizontal surface at `position` (hemispherical integral of
  // radiance x cos, XYZ: lux), by cosine-weighted view directions. Adaptive.
  ColorEstimate Irradiance(const glm::dvec3& position, const glm::dvec3& sun_direction, uint64_t stream) const;
  // Spectral radiance at the given grid wavelengths (every path carries all of them), with a
  // fixed number of paths. Fills mean[j] and stderr[j] (W m^-2 sr^-1 nm^-1).
  void SpectralRadiance(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction,
                        const std::vector<size_t>& wavelengths, uint64_t paths, uint64_t stream,
                        std::vector<double>* mean, std::vector<double>* stderr_out) const;

  // One path: L[j] for the k wavelengths idx[j] (k <= kMaxWavelengths).
  // A finite `view_t_end` restricts the first flight to [0, view_t_end] with no ground surface
  // (segment mode, as SegmentRadiance). With `L1`, L1[j] receives the path's order-1 part (the
  // sun connections made before the first scattering or reflection event: single scattering and
  // the ground's reflection of the direct sun), an unbiased estimate of the single-scattered
  // radiance from the same path (no extra random numbers).
  void TracePath(glm::dvec3 position, glm::dvec3 direction, const glm::dvec3& sun_direction, const size_t* idx, int k,
                 Pcg32& rng, double* L, double view_t_end = std::numeric_limits<double>::infinity(),
                 bool single_scattering = true, double* L1 = nullptr) const;
  // One path of the colour estimator (Radiance): the hero wavelength and its partners drawn from
  // the path's own stream (seed, stream, n), xyz = (N/K) sum_j w(lambda_j) L(lambda_j).
  void ColorPath(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction, uint64_t stream,
                 uint64_t n, double* xyz) const;
  // An observer on the ground starts 1 mm above it (as ground bounces do), so that views below
  // the horizon hit the ground at once.
  glm::dvec3 StartPoint(const glm::dvec3& position) const;
  // Ratio-tracking transmittance from `position` along `direction` to the top of the
  // atmosphere (0 if the ray hits the ground) for k wavelengths.
  void Transmittance(const glm::dvec3& position, const glm::dvec3& direction, const size_t* idx, int k, Pcg32& rng,
                     double* T) const;
  // The same up to a distance t_max along the ray (unblocked by the ground before t_max).
  // Russian roulette ends the tracking once every T[j] is below `roulette_below` (survivors are
  // reweighted): an estimate of a transmittance expected to be small passes its expected value
  // times 1e-3, so that the roulette does not turn a small but sought-after transmittance into
  // a rare large weight.
  // `majorant_scale` c >= 1 multiplies the shells' majorants: with the majorant at the
  // extinction, ratio tracking degenerates to a 0/1 estimate of relative variance e^tau - 1;
  // with c it is e^(tau / c) - 1 (homogeneous medium) at c times the lookups, which a caller
  // expecting an optical depth of several pays where it matters.
  void TransmittanceAlong(const glm::dvec3& position, const glm::dvec3& direction, double t_max, const size_t* idx,
                          int k, Pcg32& rng, double* T, double roulette_below = 1e-3, double majorant_scale = 1.0) const;

  static constexpr int kMaxWavelengths = 16;

  // The shells used for majorants (exposed for tests and the report).
  struct Shell {
    size_t level_lo, level_hi;
    double radius_lo, radius_hi;
  };
  const std::vector<Shell>& shells() const { return shells_; }

 private:
  ColorEstimate Estimate(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction,
                         uint64_t stream, bool cosine_hemisphere, double view_t_end, bool single_scattering) const;
  void SamplePath(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction, uint64_t stream,
                  uint64_t n, bool cosine_hemisphere, double view_t_end, bool single_scattering, double* xyz) const;
  size_t ShellOf(double radius) const;
  // The planet hides the whole sun disk from x: x.s < 0 and x's distance from the shadow axis
  // is below shadow_radius_m_, the planet radius shrunk by the penumbra (the disk's angular
  // radius x the longest sunlit chord through the atmosphere, + 1 m), so that points lit by
  // part of the disk are outside (the estimators stay unbiased; NEE finds the exact visibility).
  bool InEarthShadow(const glm::dvec3& x, const glm::dvec3& sun) const;
  double Majorant(size_t shell, const size_t* idx, int k) const;
  // Sun next-event estimate at a medium or ground vertex: adds to L.
  void SunNee(const glm::dvec3& x, const glm::dvec3& d, bool ground, const double* beta, const size_t* idx, int k,
              const glm::dvec3& sun, Pcg32& rng, double* L) const;
  double MixturePhase(const AtmosphereModel::Cell& cell, size_t wl, double mu) const;
  // Segment NEE (see PathTracerSettings::segment_nee) for the segment from p along d.
  // Only the part of the segment before t_cap is used.
  void SegmentSunNee(const glm::dvec3& p, const glm::dvec3& d, const double* beta, const size_t* idx, int k,
                     const glm::dvec3& sun, Pcg32& rng, double* L, double t_cap) const;

  const AtmosphereModel& model_;
  std::vector<std::array<double, 3>> xyz_weights_;
  PathTracerSettings settings_;
  std::vector<Shell> shells_;
  std::vector<double> shell_majorant_;  // [shell * n_wl + wl]
  double shadow_radius_m_ = 0.0;        // InEarthShadow
  uint64_t peak_min_paths_ = 0;         // rare_peak_events x 4 pi P_max (PathTracerSettings)
  // Built on the first guided segment NEE (sun_guided_nee): a tracer that never needs it
  // (uniform illumination, fixed-order tests) does not pay for it.
  const SunDepthTable& SunDepth() const;
  mutable std::once_flag sun_depth_once_;
  mutable std::unique_ptr<SunDepthTable> sun_depth_;
};

// Orthonormal direction helpers.
glm::dvec3 DirectionFromAngles(double zenith_rad, double azimuth_rad);  // z up, azimuth from +x
// A direction with cosine `mu` to `axis` and azimuth `phi` around it.
glm::dvec3 RotateAround(const glm::dvec3& axis, double mu, double phi);

}  // namespace skybake
