// How a render on the RGB grid {680, 550, 440} nm (the three-wavelength simplification of
// Bruneton & Neyret 2008 §2.1 and Hillaire 2016/2020) becomes a colour comparable with the
// spectral renders (docs/sky-methods.md, "RGB"; docs/color.md §5).
//
// Bruneton 2017's rule (model.cc ComputeSpectralRadianceToLuminanceFactors, "Bruneton 2016
// §14.3"): each channel's radiance L_c at lambda_c stands for
// a whole spectrum of the shape of the solar spectrum times lambda^p, scaled to pass through L_c,
//   L(lambda) ~ L_c E_0(lambda)/E_0(lambda_c) (lambda/lambda_c)^p,
// and contributes that spectrum's Linear Rec.709 channel c:
//   RGB_c = k_c L_c,   k_c = 683 lm/W int rbar_c(lambda) E_0(lambda)/E_0(lambda_c) (lambda/lambda_c)^p dlambda
// with rbar_c the observer's colour-matching functions converted to Linear Rec.709 (through OCIO).
// p = -3 for the sky (Bruneton's SKY_SPECTRAL_RADIANCE_TO_LUMINANCE; Rayleigh's lambda^-4
// softened by the aerosols' ~lambda^-1 and by multiple scattering), p = 0 for the sun. It is
// exact for spectra of that shape, and it makes the solar spectrum (p = 0) render with its true
// colour, which the plain "RGB = 683 int ybar x radiance" reading of docs/color.md §5 does not
// (it maps a flat spectrum, not sunlight, to white).
// Here the result is returned as XYZ weights of the observer (XYZ = sum_c w_c L_c, w_c = k_c x the
// XYZ of the Rec.709 primary c, both conversions by OCIO), so an RGB-grid model plugs into every
// renderer and metric that takes per-wavelength XYZ weights.
// E_0(lambda_c) is the solar table's mean over the RGB grid's 10 nm bin (spectrum/grid.h), the
// value the model's sun carries on that grid; E_0(lambda) is the table's interpolant on 1 nm
// steps over the observer's support.
#pragma once

#include <array>
#include <vector>

#include "color/color.h"
#include "spectrum/cmf.h"
#include "spectrum/spectrum.h"

namespace skybake {

// Per RGB-grid sample (R, G, B order), the observer's XYZ per unit radiance (cd/m^2 per
// W m^-2 sr^-1 nm^-1). The k_c are returned in `k` when given.
std::vector<std::array<double, 3>> RgbGridXyzWeights(const Cmf& cmf, const TabulatedSpectrum& solar,
                                                     const ColorConfig& config, double lambda_power = -3.0,
                                                     std::array<double, 3>* k = nullptr);

}  // namespace skybake
