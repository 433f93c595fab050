// How a constituent's optics are written in an atmosphere file when they are given by parameters
// instead of computed from measurements (docs/atmosphere.md, "Parametric constituents"): the
// forms the peers use (Bruneton 2017's demo, Hillaire 2020, Unreal's SkyAtmosphere; docs/peers.md).
//
//   coefficient spectrum (m^-1), exactly one of
//     {per_m: c} | {per_km: c}                     flat in wavelength
//       + optional {reference_wavelength_nm: l, power_law_exponent: k}:  c (lambda / l)^-k
//         (k = 4: Rayleigh's lambda^-4; k = the Angstrom exponent of an aerosol)
//     {rgb_per_m: [R, G, B]} | {rgb_per_km: [...]}  at 680, 550, 440 nm; only on the RGB grid
//     {table: {file, wavelength_column, value_column}}  value column in _per_m or _per_km
//   single-scattering albedo: a number in [0, 1], {rgb: [R, G, B]} or {table: {...}}
//   phase: {henyey_greenstein: {g}} | {cornette_shanks: {g}}  with g in (-1, 1), or
//          {table: {file, angle_column (_deg or _rad, 0-180 deg), value_column}}: a phase function
//          of the scattering angle, the same at every wavelength, normalised on load to 1 over the
//          sphere.
// Each form remembers the file:line it was written at, so that a problem found when it is put on a
// wavelength grid (an RGB form on a spectral grid, a table that does not cover the grid) is
// reported there.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "io/yaml.h"

namespace skybake {

// A spectral quantity tabulated in a CSV file: a wavelength column (unit from its suffix, _nm or
// _um) and a value column; `where` selects rows of long-format tables (e.g. surface = grass).
struct SpectralTableRef {
  std::filesystem::path file;
  std::string wavelength_column;
  std::string value_column;
  std::optional<std::pair<std::string, std::string>> where;  // {column, value}
};

std::optional<SpectralTableRef> ParseSpectralTable(YamlMap m);
void EmitSpectralTable(YAML::Emitter& out, const SpectralTableRef& t, const std::filesystem::path& dir);

struct CoefficientSpectrum {
  enum class Kind { kPowerLaw, kRgb, kTable };
  Kind kind = Kind::kPowerLaw;
  double value_per_m = 0.0;               // kPowerLaw: at the reference wavelength
  double reference_wavelength_nm = 550.0; // kPowerLaw
  double exponent = 0.0;                  // kPowerLaw: c (lambda / reference)^-exponent
  std::array<double, 3> rgb_per_m{};      // kRgb: R, G, B (680, 550, 440 nm)
  SpectralTableRef table;                 // kTable
  double table_unit_per_m = 1.0;          // kTable: m^-1 per unit of the value column
  FileLoc where;
};

struct AlbedoSpectrum {
  enum class Kind { kConstant, kRgb, kTable };
  Kind kind = Kind::kConstant;
  double value = 1.0;
  std::array<double, 3> rgb{};
  SpectralTableRef table;
  FileLoc where;
};

struct PhaseSpec {
  enum class Kind { kHenyeyGreenstein, kCornetteShanks, kTable };
  Kind kind = Kind::kHenyeyGreenstein;
  double g = 0.0;
  std::filesystem::path file;  // kTable
  std::string angle_column, value_column;
  FileLoc where;
};

// An aerosol layer given by its optics: extinction at the profile's peak, albedo and phase.
struct ParametricAerosolOptics {
  CoefficientSpectrum extinction;
  AlbedoSpectrum single_scattering_albedo;
  PhaseSpec phase;
};

// Each reports problems to the document's diagnostics and returns nullopt where the form is unusable.
std::optional<CoefficientSpectrum> ParseCoefficientSpectrum(YamlNode node);
std::optional<AlbedoSpectrum> ParseAlbedoSpectrum(YamlNode node);
std::optional<PhaseSpec> ParsePhaseSpec(YamlNode node);

// Canonical YAML forms (paths relative to `dir`); parsing them gives the same values.
void EmitCoefficientSpectrum(YAML::Emitter& out, const CoefficientSpectrum& c, const std::filesystem::path& dir);
void EmitAlbedoSpectrum(YAML::Emitter& out, const AlbedoSpectrum& a, const std::filesystem::path& dir);
void EmitPhaseSpec(YAML::Emitter& out, const PhaseSpec& p, const std::filesystem::path& dir);

}  // namespace skybake
