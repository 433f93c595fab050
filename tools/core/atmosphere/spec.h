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
//     - name: haze                    # or given by its optics (atmosphere/optics_spec.h)
//       extinction: {per_m: 4.44e-6}
//       single_scattering_albedo: 0.9
//       phase: {cornette_shanks: {g: 0.8}}
//       profile: {exponential: {scale_height_km: 1.2}}
//   absorbers:                        # absorption-only layers by coefficient
//     - {name: ozone, absorption: {rgb_per_km: [...]}, profile: {tent: {...}}}
//   ground: {albedo: 0.1}             # or a table
//   sun: {spectrum: {file...} | {constant_W_m2_nm: 1}, angular_diameter_deg, limb_darkening}
// Air is measured (Bodhaine's cross-section) unless it has `scattering` (the parametric form).
//
// A file may hold only some sections: the generator writes canonical *component* files (e.g.
// just planet/grid/air/ozone/aerosol profiles) in this same schema, and each tool checks that
// the sections it needs are present (RequireSections).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "atmosphere/optics_spec.h"
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
  // CO2 mixing ratio for the Rayleigh cross-section (Bodhaine et al. 1999 eq. 19), ppm by volume.
  // Default 360 ppm, the value of Bodhaine's published tables; the effect of 360 -> 420 ppm on
  // sigma is +1.6e-5 relative.
  double co2_ppm = 360.0;
  // For exponential air: number density at the base altitude (m^-3). Default: USSA76 at sea
  // level, 2.54697e25 m^-3 (computed from the USSA76 constants, atmosphere/ussa1976.h).
  double surface_number_density_m3 = 2.54697e25;
  // Parametric air (the peers' form): the Rayleigh scattering coefficient at the ground, scaled
  // with altitude by n(z) / n(0), instead of Bodhaine's cross-section times n(z); with it the
  // depolarisation factor rho_n of the Rayleigh phase (default 0, the pure (1 + mu^2) phase of
  // Bruneton 2017 and Hillaire 2020).
  std::optional<CoefficientSpectrum> scattering;
  double depolarization = 0.0;
};

// Ozone absorption cross-section: a fixed table, or the Bogumil et al. (2003) quadratic
// temperature fit sigma(T) = (C0 + C1 (T - 273.15) + C2 (T - 273.15)^2) 1e-20 cm^2 evaluated at
// a fixed temperature or at the local air temperature of each level (clamped to the fit's
// validity, 203-293 K).
struct OzoneCrossSectionSpec {
  enum class Kind { kTable, kBogumil2003 };
  Kind kind = Kind::kBogumil2003;
  SpectralTableRef table;               // kTable: value column in _cm2 or _m2
  std::filesystem::path bogumil_file;   // kBogumil2003: columns wavelength_*_nm, C0_*, C1_*, C2_*
  std::optional<double> temperature_k;  // kBogumil2003: nullopt = local air temperature
};

struct OzoneSpec {
  ProfileSpec profile = TentProfile{};
  std::optional<OzoneCrossSectionSpec> cross_section;
  // Total column in Dobson units (1 DU = 2.6867e20 molecules m^-2); the profile is rescaled to
  // it. Without it a table profile keeps its absolute values (it must then be a number density).
  std::optional<double> column_du;
};

struct AerosolScale {
  enum class Kind { kOpticalDepth550nm, kPeakNumberDensity };
  Kind kind = Kind::kOpticalDepth550nm;
  double value = 0.0;  // optical depth (1) or peak number density (m^-3)
};

// A layer is either measured (a particle type whose Mie table gives the optics, and a scale) or
// parametric (its optics written out; the extinction is at the profile's peak).
struct AerosolLayerSpec {
  std::string name;
  std::optional<std::filesystem::path> particle;
  ProfileSpec profile = ExponentialProfile{};
  std::optional<AerosolScale> scale;
  std::optional<ParametricAerosolOptics> optics;
};

// An absorption-only layer (Bruneton 2017's ozone by coefficient, Unreal's "other absorption"):
// the absorption coefficient at the profile's peak.
struct AbsorberSpec {
  std::string name;
  CoefficientSpectrum absorption;
  ProfileSpec profile = TentProfile{};
};

// Lambertian ground: a constant spectral albedo or a table.
struct GroundSpec {
  std::optional<double> albedo;
  std::optional<SpectralTableRef> albedo_table;
};

// The sun: extraterrestrial spectral irradiance at the top of the atmosphere (W m^-2 nm^-1),
// angular diameter, and limb darkening I(mu)/I(1) = sum_k a_k(lambda) mu^k from a table of
// coefficients (Neckel & Labs 1994) or none (a uniform disk).
struct SunSpec {
  SpectralTableRef spectrum;                  // unless constant_w_m2_nm
  std::optional<double> constant_w_m2_nm;     // a flat spectrum (W m^-2 nm^-1)
  double angular_diameter_deg = 0.5334;  // 2 x 0.2667 deg: 1 AU mean (Hillaire 2016 §4.1: 0.527-0.545 deg)
  std::optional<std::filesystem::path> limb_darkening_file;
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
  std::vector<AbsorberSpec> absorbers;
  std::optional<GroundSpec> ground;
  std::optional<SunSpec> sun;

  // Altitudes (m) from the ground to the top of the atmosphere with the grid step (the last
  // step may be shorter so that the top is included exactly).
  std::vector<double> AltitudeGrid() const;
};

// Names of atmospheres, aerosol layers, particle types and modes: 1-64 characters of a-z, 0-9
// and _, starting with a letter, so a name is a safe folder name and a plain word of a command
// line (no '/', '.', space or quote).
bool IsIdentifier(const std::string& s);
inline constexpr const char* kIdentifierExpected = "a lowercase identifier (a-z, 0-9, _; starting with a letter)";
// Loads and validates; throws InputError listing every problem with file:line.
AtmosphereSpec LoadAtmosphere(const std::filesystem::path& path);
AtmosphereSpec ParseAtmosphere(const YamlDocument& doc, const std::string& default_name);

// Throws InputError(file) naming every missing section among "planet", "grid", "air", "ozone",
// "ground", "sun".
void RequireSections(const AtmosphereSpec& spec, const std::vector<std::string>& sections);

// The canonical component with what profile-import needs (name, planet, grid, air, ozone,
// aerosol names and profiles), paths relative to `dir`. Comments and formatting of the source
// do not survive, so an edit that changes neither leaves these bytes unchanged.
std::string CanonicalProfilesYaml(const AtmosphereSpec& spec, const std::filesystem::path& dir);

// The canonical component with what the renderers need besides the profiles (name, planet,
// observer, air Rayleigh settings, ozone cross-section and column, aerosol names, particle files
// and scales, ground, sun); paths relative to `dir`.
std::string CanonicalRenderYaml(const AtmosphereSpec& spec, const std::filesystem::path& dir);

}  // namespace skybake
