#include "spectrum/solar.h"

#include "io/repo_paths.h"

namespace skybake {

TabulatedSpectrum LoadSolarSpectrum(const std::filesystem::path& astm_g173_csv) {
  return LoadSpectrumColumn(astm_g173_csv, kSolarColumn, /*require_non_negative=*/true);
}

Spectrum SolarIrradiance(const TabulatedSpectrum& solar, const WavelengthGrid& grid) {
  return Resample(solar, grid, Resampling::kAuto);
}

std::filesystem::path DefaultSolarPath() {
  return FindRepoFile(std::filesystem::path("atmospheres/data") / kSolarFileName);
}

}  // namespace skybake
