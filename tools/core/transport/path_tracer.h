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
//    sun's azimuth instead (twilight_guide, one-sample MIS); at a sunlit vertex a share comes
//    from the phase functions about the sun (sun_peak_guide, one-sample MIS).
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
//    (throughput x albedo; a share about the sun with sun_peak_guide).
//  - All orders: Russian roulette after `russian_roulette_depth` vertices with survival
//    probability min(1, max_j b_j x importance), weights divided by it, and in a cloudy
//    atmosphere splitting of a branch whose weight x importance exceeds split_above (both
//    unbiased).
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
#include "atmosphere/phase_peak.h"
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
  // ... at most this many where the sun-peak guide draws the peak on purpose (sun_peak_guide,
  // CloudEstimators()): the peak is then no rare event, though a few hundred paths still carry
  // the estimates' skew. Coverage of the 1 / 2 sigma intervals of 90 estimates under a thin
  // g = 0.95 cloud (PathTracerStop.ErrorBarsCoverTheSpreadUnderAThinCloud): 62 / 88 % at 64
  // paths, 63 / 89 % at 512, 63 / 92 % at 1024, 64 / 92 % at 2340 (docs/sky-render.md "Honest
  // error bars").
  uint64_t guided_peak_paths = 1024;
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
  // At a scattering or ground vertex outside the Earth's shadow, this share of the next
  // directions is drawn about the sun's direction from the phase functions of the components
  // that peak above sun_peak_min (a fixed mixture: each by its share of their column scattering
  // optical depth), the rest as before, each weighted by f / the mixture's density (one-sample MIS, Veach 1997, §9.2.4): the
  // "detector directional importance sampling" of Buras & Mayer (2011, "Efficient unbiased
  // variance reduction techniques for Monte Carlo simulations of radiative transfer in cloudy
  // atmospheres: the solution", JQSRT 112, 434-447), the sun being the detector of a backward
  // tracer. Under a cloud the light that reaches a vertex through the droplets' forward peak
  // about the sun (P(0) ~10^3 sr^-1) is otherwise found only when a direction drawn about the
  // path falls into that peak, about once in 4 pi P_max events, as a rare path of large weight;
  // with the guide such a path's weight is at most its phase / (share x the peak's density).
  // docs/sky-render.md "Clouds". 0 = no guide.
  double sun_peak_guide = 0.3;
  // The cloud estimators (sun_peak_guide, split_above, nee_roulette) act only in an atmosphere
  // with a component whose phase function peaks above this (sr^-1), and the guide draws only
  // from such components: cloud droplets (P(0) ~10^3), not air (0.12) or the usual aerosols
  // (~10), whose peak the phase-function sampling meets often enough (once in 4 pi P_max ~100
  // events). On the clear and hazed skies they buy nothing measurable: the guide moved the 95 %
  // intervals of sky-render points at a low sun from 89-91 % to 88-89 % of 150 trials, and the
  // splitting and the roulette were within the heavy tails' run-to-run spread in twilight
  // (docs/sky-render.md "Clouds").
  double sun_peak_min = kPeakedPhaseMin;
  // Splitting and Russian roulette on the weight times the importance of the direction a branch
  // leaves its vertex in (the weight window of Buras & Mayer 2011 with the guide's own density as
  // importance): the importance is max(1, sun_peak_guide x the guide's density there, sr^-1), so
  // a branch heading into the peak, whose weight the guide made small, is not rouletted back
  // into a rare path of large weight. Above split_above the branch is split into
  // ceil(weight x importance) branches of equal weight (at most 64 wait at once), each traced on
  // from the vertex; below 1 the roulette after russian_roulette_depth events survives with that
  // product. The one-sample guides (this one and twilight_guide) multiply the weight of a branch
  // they do not steer by 1 / (1 - share) per vertex; without splitting that growth is the
  // heavy tail. 0 = no splitting.
  double split_above = 2.0;
  // Segment NEE whose expected luminance (its transmittances taken as e^-tau of the expected
  // optical depths) is below this share of the estimate so far (the adaptive estimators' running
  // mean of Y, updated per batch) takes Russian roulette with survival expected / (share x mean)
  // before its two ratio-tracked transmittances are paid: deep inside a thick cloud most
  // connections see the sun through an optical depth of 10-20 and add nothing measurable.
  // 0 = every connection is traced.
  double nee_roulette = 1e-3;
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
  // Whether this atmosphere takes the cloud estimators (sun_peak_guide, split_above,
  // nee_roulette): a component's phase function peaks above sun_peak_min, sun illumination.
  bool CloudEstimators() const { return cloud_estimators_; }
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
  // radiance from the same path (no extra random numbers). A segment's sun connection whose
  // expected Y (cd/m^2 per unit path weight, transmittances at their expected depths) is below
  // `nee_floor_y` takes Russian roulette (PathTracerSettings::nee_roulette; 0 = none).
  void TracePath(glm::dvec3 position, glm::dvec3 direction, const glm::dvec3& sun_direction, const size_t* idx, int k,
                 Pcg32& rng, double* L, double view_t_end = std::numeric_limits<double>::infinity(),
                 bool single_scattering = true, double* L1 = nullptr, double nee_floor_y = 0.0) const;
  // One path of the colour estimator (Radiance): the hero wavelength and its partners drawn from
  // the path's own stream (seed, stream, n), xyz = (N/K) sum_j w(lambda_j) L(lambda_j);
  // `nee_floor_y` as for TracePath (Radiance passes nee_roulette x its running mean of Y).
  void ColorPath(const glm::dvec3& position, const glm::dvec3& direction, const glm::dvec3& sun_direction, uint64_t stream,
                 uint64_t n, double* xyz, double nee_floor_y = 0.0) const;
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
                  uint64_t n, bool cosine_hemisphere, double view_t_end, bool single_scattering, double* xyz,
                  double nee_floor_y) const;
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
  // The sun-peak guide's density (PathTracerSettings::sun_peak_guide): the phase functions of the
  // components peaking above sun_peak_min, about the sun, each weighted by its share of their
  // column scattering optical depth at the wavelength (a fixed mixture, so that a direction drawn
  // below a cloud keeps the cloud's peak in its weight). Draw at wavelength wl; the pdf (sr^-1) is the
  // mean over the nh technique wavelengths idx[0..nh).
  glm::dvec3 SamplePeakAboutSun(size_t wl, const glm::dvec3& sun, Pcg32& rng) const;
  double PeakAboutSunPdf(const size_t* idx, int nh, double cos_to_sun) const;
  // Segment NEE (see PathTracerSettings::segment_nee) for the segment from p along d.
  // Only the part of the segment before t_cap is used.
  void SegmentSunNee(const glm::dvec3& p, const glm::dvec3& d, const double* beta, const size_t* idx, int k,
                     const glm::dvec3& sun, Pcg32& rng, double* L, double t_cap, double nee_floor_y) const;

  const AtmosphereModel& model_;
  std::vector<std::array<double, 3>> xyz_weights_;
  PathTracerSettings settings_;
  std::vector<Shell> shells_;
  std::vector<double> shell_majorant_;  // [shell * n_wl + wl]
  double shadow_radius_m_ = 0.0;        // InEarthShadow
  uint64_t peak_min_paths_ = 0;         // rare_peak_events x 4 pi P_max (PathTracerSettings)
  std::vector<double> peak_weight_;     // [wl * n_components + c]: SamplePeakAboutSun's mixture
  bool cloud_estimators_ = false;       // CloudEstimators()
  double peak_guide_ = 0.0;             // sun_peak_guide in a cloudy atmosphere, else 0
  double split_above_ = 0.0;            // split_above in a cloudy atmosphere, else 0
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
