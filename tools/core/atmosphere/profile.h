// Vertical profiles: how a constituent's density varies with altitude.
//
// Kinds (YAML forms in docs/atmosphere.md):
//   ussa1976     - US Standard Atmosphere 1976 air (atmosphere/ussa1976.h); air only.
//   exponential  - n(z) = n0 exp(-(z - z0) / H)      (Bruneton 2008 §2.1; the simplified model)
//   tent         - 1 - |z - c| / w for |z - c| < w, else 0 (Bruneton 2017 demo's ozone layer)
//   table        - a measured CSV table, resampled with log-linear interpolation for densities
//                  (linear where a value is 0) or linear when asked.
// A table is validated when loaded: altitudes strictly increasing, no empty cells, no negative
// values, and coverage of the whole altitude grid (or explicit zero outside it). Each problem is
// reported with the CSV file and line.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "io/csv.h"
#include "io/interp.h"
#include "io/yaml.h"

namespace skybake {

struct Ussa1976Profile {};

struct ExponentialProfile {
  double scale_height_m = 8000.0;
  double base_altitude_m = 0.0;  // z0: the altitude where the shape equals 1
};

struct TentProfile {
  double center_m = 25000.0;
  double half_width_m = 15000.0;
};

struct TableProfile {
  std::filesystem::path file;
  std::string altitude_column;  // e.g. "altitude_km" (unit from the suffix)
  std::string value_column;     // e.g. "extinction_550nm_per_km"
  Interpolation interpolation = Interpolation::kLogLinear;
  bool zero_outside = false;    // values outside the table are 0 instead of an error
  // Air tables only: the temperature column (unit _K) beside the number density.
  std::string temperature_column;
};

using ProfileSpec = std::variant<Ussa1976Profile, ExponentialProfile, TentProfile, TableProfile>;

// Reads a profile mapping ({ussa1976: {}}, {exponential: {...}}, {tent: {...}}, {table: {...}}),
// reporting problems to the document's diagnostics. `allowed` lists the kinds accepted here.
// `air`: a table may (and must) name its temperature_column and its value column is a number density.
std::optional<ProfileSpec> ParseProfile(YamlNode node, const std::vector<std::string>& allowed, bool air = false);

// Writes the canonical YAML form (paths relative to `base_dir`) into an emitter.
void EmitProfile(YAML::Emitter& out, const ProfileSpec& spec, const std::filesystem::path& base_dir);

// The kind name ("exponential", ...).
std::string ProfileKind(const ProfileSpec& spec);

// A tabulated profile loaded and validated against its CSV file.
struct LoadedTable {
  Interpolant1D values;      // altitude (m) -> value in the column's own unit
  std::string source;        // the table's "# source:" line
  std::string value_column;
};
// Throws InputError listing every problem of the table (file:line).
LoadedTable LoadProfileTable(const TableProfile& spec);

// Samples a shape profile (exponential, tent or a loaded table) at altitudes (m).
// Table: throws InputError if the grid leaves the table and zero_outside is false.
std::vector<double> SampleShape(const ProfileSpec& spec, const std::vector<double>& altitudes_m,
                                const LoadedTable* table);

}  // namespace skybake
