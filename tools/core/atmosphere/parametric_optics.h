// The parametric forms of an atmosphere file (atmosphere/optics_spec.h) on the render grid:
// coefficient spectra (m^-1), single-scattering albedos and phase models. Data tables read are
// appended to `files_read` (for depfiles).
//
//   power law   c (lambda_i / lambda_ref)^-k at each grid sample (Bruneton 2017's demo and
//               Hillaire 2020 evaluate their coefficients at the sample wavelengths too)
//   RGB         the three values on the RGB grid {680, 550, 440} nm; an InputError at the form's
//               file:line on a spectral grid (three numbers are not a spectrum)
//   table       resampled by spectrum/spectrum.h (bin averages where the table is finer)
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "atmosphere/model.h"
#include "atmosphere/optics_spec.h"
#include "spectrum/grid.h"

namespace skybake {

std::vector<double> CoefficientOnGrid(const CoefficientSpectrum& c, const WavelengthGrid& grid,
                                      std::vector<std::filesystem::path>* files_read);
std::vector<double> AlbedoOnGrid(const AlbedoSpectrum& a, const WavelengthGrid& grid,
                                 std::vector<std::filesystem::path>* files_read);
std::shared_ptr<const PhaseModel> PhaseOnGrid(const PhaseSpec& p, const WavelengthGrid& grid,
                                              std::vector<std::filesystem::path>* files_read);

}  // namespace skybake
