// Spectral tables of an atmosphere file (a CSV's wavelength and value columns) put on the render
// grid with spectrum/spectrum.h's resampling rule, errors located at the CSV row.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "atmosphere/optics_spec.h"
#include "io/csv.h"
#include "spectrum/grid.h"
#include "spectrum/spectrum.h"

namespace skybake {

// A spectrum from two named columns: wavelength (unit from its suffix, _nm or _um) and value.
// Wavelengths must increase strictly; values >= 0 unless allow_negative, and <= max_value.
TabulatedSpectrum NamedSpectrum(const CsvTable& csv, const std::string& wavelength_column, const std::string& value_column,
                                bool allow_negative, double max_value = std::numeric_limits<double>::infinity());

// The table's value column on the grid; `where` rows selected first.
std::vector<double> TableOnGrid(const SpectralTableRef& ref, const WavelengthGrid& grid,
                                double max_value = std::numeric_limits<double>::infinity());

}  // namespace skybake
