// The complex refractive index m(lambda) = n + i k of a particle material, relative to the
// surrounding air (n_air - 1 < 3e-4 in the visible, below the accuracy of any aerosol index
// table; docs/mie.md "Particle types"), from a CSV table, a few points or a constant.
//
// Tables (atmospheres/data/*.csv, first line "# source: ..."): a wavelength column with a unit
// suffix (wavelength_um, wavelength_nm), an n column and a k column (k >= 0: absorbing media
// have k > 0 in the e^{-i omega t} convention of mie_sphere.h; OPAC's original files store -k).
// Long-format tables holding several materials are narrowed with `select: {column: value}`.
//
// Interpolation between tabulated wavelengths (docs/mie.md):
//   n: linear in wavelength;
//   k: log-linear in wavelength (k = exp of the linear interpolation of ln k), because k varies
//      by orders of magnitude between neighbouring OPAC wavelengths (water: 1e-9 at 450 nm,
//      1e-7 at 750 nm); an interval with k = 0 at one end is linear (io/interp.h).
// A wavelength outside the table is an input error (no extrapolation).
//
// Points (a retrieval's few wavelengths, e.g. AERONET's 440, 675, 870, 1020 nm):
//   points: {wavelength_nm: [440, 675, 870, 1020], n: [...], k: [...]}
//   extrapolation: nearest | linear      # required: the type says which rule it uses
// Inside the points: the table rule above (n linear, k log-linear). Outside (docs/mie.md,
// "Refractive index from a few wavelengths"):
//   nearest: the end point's value (no spectral slope beyond the measured range);
//   linear:  the end interval continued by the same rule (n linear, ln k linear in wavelength;
//            linear in k where an end has k = 0, clamped at 0), accepted only where n and k
//            stay inside their valid ranges over the grid.
#pragma once

#include <complex>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "io/error.h"
#include "io/interp.h"
#include "io/yaml.h"

namespace skybake::mie {

struct RefractiveIndex {
  enum class Kind { kTable, kConstant, kPoints };
  enum class Extrapolation { kNearest, kLinear };
  Kind kind = Kind::kConstant;

  // kTable: the file (absolute, normalised), row filters and columns.
  std::filesystem::path file;
  std::vector<std::pair<std::string, std::string>> select;
  std::string wavelength_column;  // "" = the column named wavelength_<unit>
  std::string n_column = "n_real";
  std::string k_column = "k_imag";
  // The table after loading (Load), or the points (set when parsed), wavelengths in nm.
  Interpolant1D n_table, k_table;
  bool loaded = false;
  // kPoints: the rule outside the points.
  Extrapolation extrapolation = Extrapolation::kNearest;

  // kConstant.
  double constant_n = 1.0;
  double constant_k = 0.0;

  // Where it was given (the YAML key), for coverage errors.
  FileLoc loc;

  // Reads the table (kTable); errors are located at the CSV row.
  void Load();
  // m at a wavelength inside the table (checked by the caller with Covers).
  std::complex<double> At(double wavelength_nm) const;
  bool Covers(double min_nm, double max_nm) const;
  // "wavelengths 250-1250 nm of data/x.csv" (for messages).
  std::string RangeText() const;
  // "table water.csv (component = waso, relative_humidity_percent = 70)" or "constant 1.5 + 0.01i"
  // (file name only, so that outputs do not depend on where the repository is).
  std::string Describe() const;
  // Identity of the data (file, filters, columns or the constant), for caching and comparison.
  std::string Key() const;
};

// Parses `refractive_index: {table: FILE, select: {...}, wavelength_column: .., n_column: ..,
// k_column: ..}`, `{points: {...}, extrapolation: ...}` or `{n: 1.33, k: 0}`. Problems go to the
// node's document.
RefractiveIndex ParseRefractiveIndex(const YamlNode& node);

// Writes the canonical form (paths relative to `dir`) into an emitter positioned at a value.
void EmitRefractiveIndex(YAML::Emitter& out, const RefractiveIndex& ri, const std::filesystem::path& dir);

}  // namespace skybake::mie
