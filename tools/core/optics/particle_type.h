// Aerosol particle types (particles/*.yaml): an external mixture of modes of homogeneous
// spheres, each a log-normal or a tabulated size distribution (optics/size_table.h) with a
// complex refractive index. Read by mie-tables; referenced by atmospheres through
// `aerosols[].particle` (docs/mie.md has the full schema).
//
//   refractive_index: {table: ../atmospheres/data/water.csv}   # default for every mode
//   modes:
//     - name: fine
//       refractive_index: {...}        # optional, overrides the default
//       basis: volume                  # number | volume: the distribution the median refers to
//       median_radius_um: 0.12         # or effective_radius_um (then no basis)
//       ln_sigma_g: 0.45               # or sigma_g (>1): exactly one, named
//       r_min_um: 0.05                 # truncation; results are per particle inside
//       r_max_um: 15.0
//       weight: {relative_volume: 1.0} # number_density_cm3 | relative_number |
//                                      # volume_um3_per_cm3 | relative_volume (same key in every mode)
//     - name: measured
//       size_table: data/site.csv      # instead of basis .. r_max_um: the table's radii bound it
//       weight: {relative_volume: 1.0}
//
// The log-normal family (Hansen & Travis 1974, Space Sci. Rev. 16,
// 527, eqs. 2.53-2.56): with s = ln sigma_g and r_g the number median radius,
//   dN/dln r = N / (sqrt(2 pi) s) exp(-(ln r - ln r_g)^2 / (2 s^2)),
//   volume median r_V = r_g e^{3 s^2},  effective radius r_eff = <r^3>/<r^2> = r_g e^{5 s^2 / 2},
//   effective variance v_eff = e^{s^2} - 1,  mean radius <r> = r_g e^{s^2/2},
//   <r^k> = r_g^k e^{k^2 s^2 / 2}  (Hatch-Choate).
// Truncated to [r_min, r_max] with a = (ln r_min - ln r_g)/s, b = (ln r_max - ln r_g)/s:
//   fraction of the particles inside Z = Phi(b) - Phi(a),
//   <r^k>_inside = r_g^k e^{k^2 s^2/2} [Phi(b - k s) - Phi(a - k s)] / Z.
// A tabulated mode's moments are the table's (size_table.h); its bounds are its first and last
// radius and it holds all of its particles.
// Weights count the particles (or their volume) inside [r_min, r_max]; a mode's number fraction
// in the mixture is w_i / sum w_j for number weights, and (w_i/<v>_i) / sum (w_j/<v>_j) for volume
// weights, <v> the mean particle volume inside the bounds.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/error.h"
#include "optics/refractive_index.h"
#include "optics/size_table.h"

namespace skybake::mie {

enum class WeightKind { kNumberDensityCm3, kRelativeNumber, kVolumeUm3PerCm3, kRelativeVolume };
// The YAML key of a weight kind, e.g. "relative_volume".
const char* WeightKey(WeightKind kind);
bool IsVolumeWeight(WeightKind kind);

// One mode of the mixture: a log-normal (the fields below) or a table (`table`; then the
// log-normal fields are unset and r_min_um, r_max_um are the table's first and last radius).
struct SizeMode {
  std::string name;
  FileLoc loc;  // the mode's mapping
  std::optional<SizeTable> table;

  // Centre: a median (with its basis) or an effective radius, as written (um).
  std::optional<SizeBasis> basis;
  std::optional<double> median_radius_um;
  std::optional<double> effective_radius_um;
  // Width as written: sigma_g (> 1) or ln_sigma_g (> 0).
  bool width_is_sigma_g = false;
  double width_value = 0.0;
  double r_min_um = 0.0, r_max_um = 0.0;
  WeightKind weight_kind = WeightKind::kRelativeNumber;
  double weight = 0.0;
  RefractiveIndex index;

  bool IsTable() const { return table.has_value(); }
  // s = ln sigma_g (log-normal modes only, as the next five).
  double LnSigma() const;
  // Log-normal algebra (see the header comment), radii in um, untruncated unless named "Inside".
  double NumberMedianRadiusUm() const;
  double VolumeMedianRadiusUm() const;
  double EffectiveRadiusUm() const;
  double EffectiveVariance() const;
  double MeanRadiusUm() const;
  // Fraction of the log-normal's particles inside [r_min, r_max] (1 for a table).
  double NumberFractionInside() const;
  // <r^k> of the particles inside the bounds, um^k.
  double MomentInsideUm(int k) const;
  // Mean particle volume inside the bounds, um^3.
  double MeanVolumeInsideUm3() const;
};

struct ParticleType {
  std::string name;            // the file stem
  std::filesystem::path file;  // the YAML it was read from
  std::vector<SizeMode> modes;
  std::vector<std::filesystem::path> inputs;  // the YAML and every refractive-index and size table read

  // Number fraction of each mode in the mixture (sums to 1).
  std::vector<double> NumberFractions() const;
  // Mean particle volume of the mixture, um^3.
  double MeanVolumeUm3() const;
};

// Loads, validates and reads the refractive-index tables; every problem is reported with
// file:line (InputError).
ParticleType LoadParticleType(const std::filesystem::path& path);
ParticleType ParseParticleType(const YamlDocument& doc, const std::string& name);

// Throws InputError (at the refractive_index key of the YAML) when a mode's index table does not
// cover [min_nm, max_nm].
void CheckWavelengthCoverage(const ParticleType& type, double min_nm, double max_nm);

// The type with only the mode `mode_name` (weight irrelevant then); throws UsageError if absent.
ParticleType SelectMode(const ParticleType& type, const std::string& mode_name);

// The canonical file: every mode with its resolved refractive index, numbers as written
// (FormatExact), table paths relative to `dir`, no comments. Equal content -> equal bytes.
std::string CanonicalParticleYaml(const ParticleType& type, const std::filesystem::path& dir);

}  // namespace skybake::mie
