// A tabulated size distribution (a measured one, e.g. AERONET's 22 retrieval bins): a CSV of
// radii and dV/d ln r or dN/d ln r, used by a mode of a particle type (`size_table: FILE`;
// docs/mie.md, "Tabulated size distributions").
//
// File (the CSV convention of io/csv.h):
//   # source: where the numbers come from
//   radius_um,dV_dlnr_um3_um2        <- a radius column (radius_um or radius_nm) and exactly one
//   0.05,0.0012                         density column dV_dlnr_<unit> (volume basis) or
//   ...                                 dN_dlnr_<unit> (number basis); the unit suffix is
//                                       required and only the shape matters (the mode's weight
//                                       sets the amount)
// Radii strictly increasing in [1e-4, 100] um, at least 2 rows, densities >= 0 and not all 0
// (AERONET's fill value -999 is reported at its row).
//
// Interpolation, with u = ln r: the density in the table's own basis is linear in u between
// neighbouring radii and zero outside [r_1, r_n] (docs/mie.md, "Tabulated size distributions":
// the simplest rule that reproduces the table at its radii, keeps the density >= 0 and adds no
// shape the measurement does not hold; AERONET's retrieval gives dV/d ln r at 22 radii
// log-spaced over 0.05-15 um, Dubovik & King 2000, JGR 105, 20673). The number density of a
// volume table is n(u) = (dV/d ln r)(u) / (4/3 pi r^3).
// Moments: <r^k> = int n(u) e^{k u} du / int n(u) du, exact per interval (a linear function
// times an exponential), so the mean volume and effective radius carry no quadrature error.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/error.h"

namespace skybake::mie {

enum class SizeBasis { kNumber, kVolume };

struct SizeTable {
  std::filesystem::path file;  // absolute, normalised
  FileLoc loc;                 // the size_table key in the YAML
  SizeBasis basis = SizeBasis::kVolume;
  std::string density_column;  // e.g. "dV_dlnr_um3_um2"
  std::string source;          // the CSV's "# source:" text
  std::vector<double> ln_r_um;  // ln(r / 1 um), strictly increasing
  std::vector<double> density;  // as written, in the table's basis (>= 0)

  // Reads and validates the CSV; errors at the CSV row (InputError).
  void Load();
  bool loaded() const { return !ln_r_um.empty(); }

  double r_min_um() const;
  double r_max_um() const;
  // dN/d ln r at u = ln(r / 1 um) in the table's units (per um^3 for a volume table): 0 outside.
  double NumberDensity(double ln_r_um_value) const;
  // int n(u) e^{k u} du over the table (k = 0: the number of particles, in the table's units).
  double NumberMoment(int k) const;
  // <r^k> of the particles, um^k.
  double MomentUm(int k) const { return NumberMoment(k) / NumberMoment(0); }
  // Mean particle volume, um^3.
  double MeanVolumeUm3() const;
};

// int_{u0}^{u1} (f0 + (f1 - f0)(u - u0)/(u1 - u0)) e^{c u} du, exact (series near c (u1-u0) = 0).
double LinearTimesExpIntegral(double u0, double u1, double f0, double f1, double c);

}  // namespace skybake::mie
