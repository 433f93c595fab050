// CSV tables of measured data.
//
// Format (the convention of every table in atmospheres/data/):
//   # source: <where the numbers come from>      <- required first line
//   # any further comment lines
//   name_unit,other_name_unit,...                  <- header: unit-bearing column names
//   1.0,2.5e-3,...                                 <- rows; empty cells are allowed (a "gap")
// Column names carry their unit as a suffix (altitude_km, number_density_cm3, sigma_cm2, ...);
// ColumnIn() finds a column by its base name and converts it to SI using that suffix.
// Errors name the file and the line: `data.csv:14: column 'altitude_km': expected a number,
// got "x"`.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/error.h"

namespace skybake {

// The physical quantity a column holds, for unit conversion.
enum class Quantity {
  kLength,          // SI: m        suffixes: _m, _km, _um, _nm
  kWavelength,      // SI: nm (wavelengths stay in nm in skybake)   _nm, _um
  kNumberDensity,   // SI: m^-3     _m3, _cm3 (meaning "per m^3", "per cm^3")
  kInverseLength,   // SI: m^-1     _per_m, _per_km, _m-1, _km-1
  kCrossSection,    // SI: m^2      _m2, _cm2, _um2
  kTemperature,     // SI: K        _K
  kPressure,        // SI: Pa       _Pa, _hPa, _mb
  kMassDensity,     // SI: kg m^-3  _kg_m3, _g_cm3
  kDimensionless,   // no unit      any suffix or none; value as is
};

// Scale factor from the unit named by `suffix` to the SI unit of `q`, or nullopt if unknown.
std::optional<double> UnitScale(Quantity q, const std::string& suffix);
// The accepted suffixes for q, for messages ("_km or _m").
std::string UnitSuffixes(Quantity q);

class CsvTable {
 public:
  // Reads a table; throws InputError for a missing file, a missing "# source:" line, an empty
  // header, or rows with the wrong number of cells.
  static CsvTable Load(const std::filesystem::path& path);
  static CsvTable Parse(const std::string& text, const std::string& display_name);

  const std::string& display_name() const { return display_name_; }
  const std::string& source() const { return source_; }
  const std::vector<std::string>& columns() const { return columns_; }
  size_t rows() const { return cells_.size(); }
  int header_line() const { return header_line_; }
  int row_line(size_t row) const { return row_lines_[row]; }
  const std::string& cell(size_t row, size_t col) const { return cells_[row][col]; }

  // Index of a column by exact name, or -1.
  int ColumnIndex(const std::string& name) const;

  // Numbers of a column (exact name), as written. Empty cells are errors unless allow_empty,
  // in which case they come back as NaN. Errors are added to `diags` with the row's line.
  std::vector<double> Numbers(const std::string& name, Diagnostics& diags,
                              bool allow_empty = false) const;

  // Finds the column "<base>_<unit>" for a known unit of `q` and returns its values in SI.
  // Reports a missing column (listing what exists) to diags.
  struct SiColumn {
    std::string name;            // the full column name found
    std::vector<double> values;  // converted to SI
  };
  std::optional<SiColumn> ColumnIn(const std::string& base, Quantity q, Diagnostics& diags,
                                   bool allow_empty = false) const;
  // Like ColumnIn but for an exact column name whose suffix gives the unit.
  std::optional<SiColumn> NamedColumnIn(const std::string& name, Quantity q, Diagnostics& diags,
                                        bool allow_empty = false) const;

  // Rows whose string column `key` equals `value` (for long-format tables), as a new table.
  CsvTable Filter(const std::string& key, const std::string& value) const;

  FileLoc LocOfRow(size_t row) const { return FileLoc{display_name_, row_lines_[row]}; }
  FileLoc LocOfHeader() const { return FileLoc{display_name_, header_line_}; }

 private:
  std::string display_name_;
  std::string source_;
  std::vector<std::string> columns_;
  std::vector<std::vector<std::string>> cells_;
  std::vector<int> row_lines_;
  int header_line_ = 0;
};

}  // namespace skybake
