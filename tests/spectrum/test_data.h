// Paths of the project's data tables for the spectrum/colour tests.
#pragma once

#include <string>

#include "spectrum/cmf.h"

namespace skybake::testing_data {

inline std::string DataFile(const std::string& name) {
  return std::string(SKYBAKE_SOURCE_DIR) + "/atmospheres/data/" + name;
}

// Loaded once per test binary (the tables are immutable).
inline const Cmf& LoadedCmf(Observer observer) {
  static const Cmf k2006 = Cmf::Load(DataFile(CmfFileName(Observer::kCie2006_2deg)), Observer::kCie2006_2deg);
  static const Cmf k1931 = Cmf::Load(DataFile(CmfFileName(Observer::kCie1931_2deg)), Observer::kCie1931_2deg);
  return observer == Observer::kCie2006_2deg ? k2006 : k1931;
}

// Planck's law: spectral radiance of a blackbody, W m^-2 sr^-1 nm^-1 (CODATA 2018 exact h, c, k).
inline double PlanckRadiance(double wavelength_nm, double temperature_k) {
  const double h = 6.62607015e-34, c = 2.99792458e8, k = 1.380649e-23;
  const double l = wavelength_nm * 1e-9;
  return 2.0 * h * c * c / (l * l * l * l * l) / std::expm1(h * c / (l * k * temperature_k)) * 1e-9;
}

}  // namespace skybake::testing_data
