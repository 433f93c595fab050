// The vertical profiles of one atmosphere on its altitude grid (what profile-import writes and
// the renderers read):
//   air.number_density    m^-3   US Std 1976, exponential (isothermal) or a measured table
//   air.temperature       K      kinetic temperature
//   air.pressure          Pa
//   air.mass_density      kg m^-3
//   ozone.number_density  m^-3   rescaled to the requested column (DU)
//   absorber.<name>.shape m^-1   an absorbing layer's profile, normalised like the aerosols'
//   aerosol.<name>.shape  m^-1   the layer's profile normalised to a unit column:
//                                 integral of shape dz over the grid = 1 (trapezoid rule).
//                                 The renderer multiplies by the layer's column number
//                                 (from its optical depth or peak density) to get m^-3.
// Column integrals use the trapezoid rule on the output grid, i.e. exactly what a renderer that
// interpolates linearly between grid levels sees.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "atmosphere/spec.h"
#include "io/exr.h"

namespace skybake {

// 1 Dobson unit = 2.6867e20 molecules m^-2 (0.01 mm of ozone at STP: Loschmidt's number
// 2.6867e25 m^-3 x 1e-5 m; WMO definition).
inline constexpr double kDobsonUnitM2 = 2.6867e20;

struct VerticalProfiles {
  std::vector<double> altitude_m;
  std::vector<double> air_number_density_m3;
  std::vector<double> air_temperature_k;
  std::vector<double> air_pressure_pa;
  std::vector<double> air_mass_density_kg_m3;
  bool has_ozone = false;
  std::vector<double> ozone_number_density_m3;
  double ozone_column_du = 0.0;
  struct Aerosol {
    std::string name;
    std::vector<double> shape_per_m;  // unit column
    double raw_column = 0.0;          // integral of the unscaled profile (profile unit x m)
    double raw_peak = 0.0;            // max of the unscaled profile on the grid
  };
  std::vector<Aerosol> aerosols;
  std::vector<Aerosol> absorbers;   // absorbing layers' shapes, the same normalisation
  std::vector<std::filesystem::path> inputs_read;  // data tables read (for depfiles)
};

// Computes the profiles; throws InputError for bad tables (file:line) or impossible requests
// (e.g. an aerosol profile that is zero everywhere on the grid).
VerticalProfiles ComputeProfiles(const AtmosphereSpec& spec);

// Table form (axis 0: altitude in m) with the channels above; and back (for the renderers).
ExrTable ProfilesToTable(const VerticalProfiles& p);
VerticalProfiles ProfilesFromTable(const ExrTable& t, const std::string& display_name);

}  // namespace skybake
