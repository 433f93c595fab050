// The extraterrestrial solar spectral irradiance: ASTM G173-03 (docs/color.md §2.2).
//
// Source: ASTM G173-03, Standard Tables for Reference Solar Spectral Irradiances, extraterrestrial
// column (from SMARTS 2.9.2 / NREL), 280-4000 nm at 0.5 nm (to 400 nm), 1 nm (to 1700 nm) and
// 5 nm (to 4000 nm), W m^-2 nm^-1 at the mean Sun-Earth distance (1 AU); file
// atmospheres/data/astm_g173_03_solar_spectrum.csv, column extraterrestrial_W_m2_nm. ASTM gives
// 1366.1 W/m² for the whole spectrum; the tabulated 280-4000 nm hold 1347.9 W/m² (trapezoid), the
// rest lies beyond 4 µm (tests/spectrum/solar_test.cpp checks this against Planck's law).
// The GT7 sky renderer uses the same table (GT7 sky talk, "ASTM G173-03
// Extraterrestrial Spectrum").
//
// On a grid it is bin-averaged wherever the table resolves the bins (spectrum.h kAuto): on a 5 nm
// grid each value is the mean irradiance over [λ - 2.5, λ + 2.5] nm, so Σ E_i Δλ_i is the
// table's integral over the covered range. The sun's radiance for a renderer (E / Ω_sun) is
// the renderer's business.
#pragma once

#include <filesystem>

#include "spectrum/grid.h"
#include "spectrum/spectrum.h"

namespace skybake {

inline constexpr const char* kSolarFileName = "astm_g173_03_solar_spectrum.csv";
inline constexpr const char* kSolarColumn = "extraterrestrial_W_m2_nm";

// The ASTM G173 extraterrestrial column as a table (W m^-2 nm^-1).
TabulatedSpectrum LoadSolarSpectrum(const std::filesystem::path& astm_g173_csv);
// The same, resampled on `grid` (kAuto: bin averages on grids coarser than 2 nm; on the RGB grid
// the 10 nm bins around 680, 550, 440 nm).
Spectrum SolarIrradiance(const TabulatedSpectrum& solar, const WavelengthGrid& grid);
// atmospheres/data/astm_g173_03_solar_spectrum.csv found by FindRepoFile.
std::filesystem::path DefaultSolarPath();

}  // namespace skybake
