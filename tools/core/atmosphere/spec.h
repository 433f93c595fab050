// The atmosphere file (atmospheres/*.yaml): what the user writes, validated with file:line.
//
// Schema (docs/atmosphere.md has the full reference with units and sources):
//   name: clear                       # optional; default: the file name
//   planet: {radius_km: 6371, top_km: 100}
//   observer: {altitude_km: 0}        # optional, default 0
//   grid: {altitude_step_m: 100}      # optional here; pipeline.yaml gives the default
//   air: {profile: ussa1976}          # or {profile: {exponential: {scale_height_km: 8}}}
//   ozone: {profile: {table: ...} | {tent: ...}, column_du: 300}     # optional section
//   aerosols:                         # any number of layers, each with a unique name
//     - name: boundary_layer
//       particle: ../particles/continental.yaml    # particle type (mie-tables)
//       profile: {table: {...}} | {exponential: {...}} | {tent: {...}}
//       scale: {optical_depth_550nm: 0.1} | {peak_number_density_cm3: 3000}
// Later sections (ground, sun, ...) are added by the issues that use them.
//
// A file may hold only some sections: the generator writes canonical *component* files (e.g.
// just planet/grid/air/ozone/aerosol profiles) in this same schema, and each tool checks that
// the sections it needs are present (RequireSections).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "atmosphere/profile.h"
#include "io/yaml.h"

namespace skybake {

struct PlanetSpec {
  double radius_m = 0.0;
  double top_m = 0.0;  // top of the atmosphere above the ground
};

struct GridSpec {
  double altitude_step_m = 100.0;
};

struct AirSpec {
  ProfileSpec profile = Ussa1976Profile{};
  // For exponential air: number density at the base altitude (m^-3). Default: USSA76 at sea
  // level, 2.54697e25 m^-3 (computed from the USSA76 constants, atmosphere/ussa1976.h).
  double surface_number_density_m3 = 2.54697e25;
};

struct OzoneSpec {
  ProfileSpec profile = TentProfile{};
  // Total column in Dobson units (1 DU = 2.6867e20 molecules m^-2); the profile is rescaled to
  // it. Without it a table profile keeps its absolute values (it must then be a number density).
  std::optional<double> column_du;
};

struct AerosolScale {
  enum class Kind { kOpticalDepth550nm, kPeakNumberDensity };
  Kind kind = Kind::kOpticalDepth550nm;
  double value = 0.0;  // optical depth (1) or peak number density (m^-3)
};

struct AerosolLayerSpec {
  std::string name;
  std::optional<std::filesystem::path> particle;
  ProfileSpec profile = ExponentialProfile{};
  std::optional<AerosolScale> scale;
};

struct AtmosphereSpec {
  std::string name;
  std::filesystem::path file;  // where it was read from
  std::optional<PlanetSpec> planet;
  double observer_altitude_m = 0.0;
  std::optional<GridSpec> grid;
  std::optional<AirSpec> air;
  std::optional<OzoneSpec> ozone;
  std::vector<AerosolLayerSpec> aerosols;

  // Altitudes (m) from the ground to the top of the atmosphere with the grid step (the last
  // step may be shorter so that the top is included exactly).
  std::vector<double> AltitudeGrid() const;
};

// Loads and validates; throws InputError listing every problem with file:line.
AtmosphereSpec LoadAtmosphere(const std::filesystem::path& path);
AtmosphereSpec ParseAtmosphere(const YamlDocument& doc, const std::string& default_name);

// Throws InputError(file) naming the first missing section among "planet", "grid", "air".
void RequireSections(const AtmosphereSpec& spec, const std::vector<std::string>& sections);

// The canonical component with what profile-import needs (name, planet, grid, air, ozone,
// aerosol names and profiles), paths relative to `dir`. Comments and formatting of the source
// do not survive, so an edit that changes neither leaves these bytes unchanged.
std::string CanonicalProfilesYaml(const AtmosphereSpec& spec, const std::filesystem::path& dir);

}  // namespace skybake
