#include "atmosphere/parametric_optics.h"

#include <cmath>

#include <fmt/format.h>

#include "atmosphere/table_on_grid.h"
#include "atmosphere/tabulated_phase.h"

namespace skybake {

namespace {

void RequireRgbGrid(const WavelengthGrid& grid, const FileLoc& where) {
  if (grid.kind() != WavelengthGrid::Kind::kRgb) {
    throw InputError(where, "an RGB form (three values at 680, 550, 440 nm) needs --wavelengths rgb; the grid is " +
                                grid.Describe() + " (give a spectrum: per_m with a power law, or a table)");
  }
}

}  // namespace

std::vector<double> CoefficientOnGrid(const CoefficientSpectrum& c, const WavelengthGrid& grid,
                                      std::vector<std::filesystem::path>* files_read) {
  std::vector<double> out(grid.size());
  switch (c.kind) {
    case CoefficientSpectrum::Kind::kPowerLaw:
      for (size_t i = 0; i < grid.size(); ++i) {
        out[i] = c.exponent == 0.0 ? c.value_per_m
                                   : c.value_per_m * std::pow(grid[i] / c.reference_wavelength_nm, -c.exponent);
      }
      break;
    case CoefficientSpectrum::Kind::kRgb:
      RequireRgbGrid(grid, c.where);
      for (size_t i = 0; i < 3; ++i) out[i] = c.rgb_per_m[i];
      break;
    case CoefficientSpectrum::Kind::kTable: {
      std::vector<double> v = TableOnGrid(c.table, grid);
      if (files_read) files_read->push_back(c.table.file);
      for (size_t i = 0; i < grid.size(); ++i) out[i] = v[i] * c.table_unit_per_m;
      break;
    }
  }
  for (double v : out) {
    if (!std::isfinite(v)) {
      throw InputError(c.where, "the coefficient is not finite on the wavelength grid (power law out of range)");
    }
  }
  return out;
}

std::vector<double> AlbedoOnGrid(const AlbedoSpectrum& a, const WavelengthGrid& grid,
                                 std::vector<std::filesystem::path>* files_read) {
  switch (a.kind) {
    case AlbedoSpectrum::Kind::kConstant: return std::vector<double>(grid.size(), a.value);
    case AlbedoSpectrum::Kind::kRgb: RequireRgbGrid(grid, a.where); return {a.rgb[0], a.rgb[1], a.rgb[2]};
    case AlbedoSpectrum::Kind::kTable: {
      std::vector<double> v = TableOnGrid(a.table, grid, 1.0);  // an albedo: [0, 1]
      if (files_read) files_read->push_back(a.table.file);
      return v;
    }
  }
  return {};
}

std::shared_ptr<const PhaseModel> PhaseOnGrid(const PhaseSpec& p, const WavelengthGrid& grid,
                                              std::vector<std::filesystem::path>* files_read) {
  switch (p.kind) {
    case PhaseSpec::Kind::kHenyeyGreenstein:
      return std::make_shared<HenyeyGreensteinPhase>(std::vector<double>(grid.size(), p.g));
    case PhaseSpec::Kind::kCornetteShanks:
      return std::make_shared<CornetteShanksPhase>(std::vector<double>(grid.size(), p.g));
    case PhaseSpec::Kind::kTable:
      if (files_read) files_read->push_back(p.file);
      return std::make_shared<TabulatedPhase>(TabulatedPhase::Load(p.file, p.angle_column, p.value_column));
  }
  return nullptr;
}

}  // namespace skybake
