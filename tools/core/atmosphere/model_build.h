// Builds the renderers' AtmosphereModel from measured inputs (docs/atmosphere.md):
//   air     n_air(z) sigma_R(lambda)  (optics/rayleigh.h, Bodhaine 1999), depolarised Rayleigh phase
//   ozone   n_O3(z) sigma_O3(lambda, T(z))  (Bogumil et al. 2003 fit at the local temperature,
//           or a fixed table), absorption only
//   aerosol N_col shape(z) C_sca(lambda), N_col shape(z) C_abs(lambda), tabulated phase; the
//           column number N_col from the layer's scale: optical depth at 550 nm
//           (N_col = tau_550 / C_ext(550 nm)) or peak number density (N_col = n_peak / max shape)
//   ground  spectral Lambertian albedo (constant or a table, resampled on the grid)
//   sun     ASTM G173 extraterrestrial irradiance bin-averaged on the grid, angular diameter,
//           Neckel & Labs (1994) limb darkening interpolated in wavelength
// Spectral tables are resampled on the render grid by spectrum/spectrum.h (bin averages where the
// table is finer than the grid, linear interpolation otherwise); the ozone fit coefficients are
// bin-averaged, which bin-averages sigma(T) exactly since it is linear in them.
//
// Options switch the simplifications of sky-render part 2 (no ozone; Henyey-Greenstein etc. are
// chosen by the caller through the aerosol phase models).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atmosphere/model.h"
#include "atmosphere/spec.h"
#include "atmosphere/vertical_profiles.h"
#include "spectrum/grid.h"

namespace skybake {

// What the Mie tables say about one aerosol layer's particle type, on the render grid.
struct AerosolOptics {
  std::string layer;                            // the atmosphere's aerosol layer name
  std::vector<double> cext_m2, csca_m2;         // per particle, per grid wavelength
  double cext_550nm_m2 = 0.0;                   // for optical-depth scaling
  std::shared_ptr<const PhaseModel> phase;      // per grid wavelength
};

struct ModelOptions {
  bool ozone = true;      // false: drop ozone absorption (a simplification to measure)
  bool aerosols = true;   // false: a pure Rayleigh (+ ozone) sky
};

// Throws InputError (file:line of the table) for data that do not cover the grid, and
// InputError(atmosphere file) for missing sections or aerosol layers without optics.
// `files_read` receives every data table opened (for depfiles).
AtmosphereModel BuildAtmosphereModel(const AtmosphereSpec& spec, const VerticalProfiles& profiles,
                                     const WavelengthGrid& grid, const std::vector<AerosolOptics>& aerosols,
                                     const ModelOptions& options, std::vector<std::filesystem::path>* files_read);

// Neckel & Labs (1994) limb-darkening coefficients a_0..a_5 interpolated linearly in wavelength
// and renormalised to sum 1 (I(1) = 1), per grid wavelength.
std::vector<std::array<double, 6>> LoadLimbDarkening(const std::filesystem::path& csv, const WavelengthGrid& grid);

}  // namespace skybake
