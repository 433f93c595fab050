// How far a sky is from a reference sky: the metrics of the speed-vs-accuracy chart
// (bench/sky_chart.cpp) and of `sky-render budget` (transport/budget.h); docs/sky-methods.md,
// "Metrics", defines them.
//
// Directions: a fixed set over the upper hemisphere (the sky; the ground is not compared): the
// zenith and rows at view zenith 10, 20, ..., 80, 85, 88 deg, each at azimuths 0, 22.5, ..., 180 deg
// from the sun (the radiance is symmetric about the sun's vertical plane, so the half-sky
// represents the whole). Each direction carries the solid angle of its cell (rows split at the
// mid-angles, the last row up to the horizon; azimuth cells 22.5 deg wide, half that at 0 and
// 180 deg, doubled for the mirrored half), so the statistics are sky averages, not averages over
// a set that is denser near the horizon.
//
// Per direction d outside the aureole (angular distance to the sun centre > 1 deg, where every
// method's disk handling and the reference's noise dominate), with Y the luminance:
//   e_d = Y_test/Y_ref - 1
//   RMS = sqrt(sum_d w_d e_d^2 / sum_d w_d),  max = max_d |e_d|
//   RMS_corrected = sqrt(max(0, RMS^2 - sum_d w_d (sigma_d/Y_ref,d)^2 / sum_d w_d))
//     (the reference's own noise sigma_d inflates RMS^2 by its mean square on average; the
//     correction removes it. The max is not corrected: the reference noise is reported beside it)
//   colour: both colours in Linear Rec.2020 (OCIO, from the observer's XYZ), the test scaled to the
//     reference's luminance, c_d = |RGB_test Y_ref/Y_test - RGB_ref| / (sqrt(3) Y_ref), and
//     colour_RMS = sqrt(sum_d w_d c_d^2 / sum_d w_d): a chromaticity error independent of the
//     luminance error, in units of the luminance (0.01 = a 1 % channel error at equal luminance);
//   du'v': the CIE 1976 u'v' distance in the CIE-XYZ-D65 reference (JND ~0.004), RMS over the sky.
#pragma once

#include <array>
#include <vector>

#include "color/color.h"

namespace skybake {

struct SkyDirections {
  std::vector<std::array<double, 3>> dirs;  // local frame (+z zenith, +x the sun's azimuth)
  std::vector<double> theta_deg, phi_deg;   // view zenith, azimuth from the sun
  std::vector<double> solid_angle_sr;       // the cell, doubled for the mirrored half
};

// The chart's direction set (see above): 91 directions.
SkyDirections ChartDirections();

struct SkyError {
  double rms = 0.0, rms_corrected = 0.0, max = 0.0;
  double ref_noise_rms = 0.0;   // sqrt(weighted mean (sigma/Y)^2) of the reference
  double ref_noise_max = 0.0;   // largest sigma/Y of the reference
  double color_rms = 0.0;       // Rec.2020, at equal luminance
  double duv_rms = 0.0;
  size_t directions = 0;        // compared (outside the aureole)
};

struct SkyCompareInput {
  const SkyDirections* directions = nullptr;
  double sun_zenith_rad = 0.0;
  double aureole_deg = 1.0;
  const std::vector<std::array<double, 3>>* ref_xyz = nullptr;  // observer XYZ, cd/m^2
  const std::vector<double>* ref_y_stderr = nullptr;            // cd/m^2 (may be null: exact reference)
  const std::vector<std::array<double, 3>>* test_xyz = nullptr;
  const ColorProcessor* to_rec2020 = nullptr;   // observer XYZ -> Linear Rec.2020
  const ColorProcessor* to_reference = nullptr; // observer XYZ -> CIE-XYZ-D65
};

// `per_direction` (optional) receives e_d per direction (NaN inside the aureole).
SkyError CompareSkies(const SkyCompareInput& in, std::vector<double>* per_direction = nullptr);

// Spectral radiance [d * n_wl + wl] -> observer XYZ per direction.
std::vector<std::array<double, 3>> SpectralToXyz(const std::vector<double>& radiance,
                                                 const std::vector<std::array<double, 3>>& weights);

}  // namespace skybake
