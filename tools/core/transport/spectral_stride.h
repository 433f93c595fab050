// Spectral sub-sampling of a deterministic sky method: the atmosphere's transfer (radiance per
// unit solar irradiance) is smooth in wavelength - Rayleigh ~ lambda^-4, the aerosols' Mie
// coefficients, ozone's Chappuis band - while the sun's spectrum is not (ASTM G173's Fraunhofer
// structure at 5 nm). So the method is built on every k-th wavelength of the grid (and the last)
// with a unit sun, and the full-grid radiance is E_sun(lambda) x the transfer interpolated
// log-log between those nodes (exact for a power law; linear where a value is 0). Costs drop
// ~k-fold (the table build and the march are linear in the wavelength count); the error is
// measured in tests/transport/spectral_stride_test.cpp and docs/sky-methods.md.
#pragma once

#include <memory>
#include <vector>

#include "transport/sky_method.h"

namespace skybake {

// Every `stride`-th index of 0..n-1, always with n-1.
std::vector<size_t> StrideIndices(size_t n, int stride);

// The model on a subset of its wavelengths (indices increasing); phases and per-wavelength data
// are selected, not resampled. With `unit_sun` the sun's irradiance is 1 at every wavelength.
AtmosphereModel SubsetWavelengths(const AtmosphereModel& model, const std::vector<size_t>& indices, bool unit_sun);

// `inner` (a registered method name) built on the strided model; Radiance and SegmentRadiance
// return the full grid.
std::unique_ptr<SkyMethod> MakeSpectralStrideMethod(const std::string& inner, const AtmosphereModel& model,
                                                    const SkyMethodOptions& options, const ProgressFn& progress);

}  // namespace skybake
