#include "atmosphere/table_on_grid.h"

#include <fmt/format.h>

#include "io/yaml.h"

namespace skybake {

TabulatedSpectrum NamedSpectrum(const CsvTable& csv, const std::string& wavelength_column, const std::string& value_column,
                                bool allow_negative, double max_value) {
  Diagnostics d;
  std::optional<CsvTable::SiColumn> wl = csv.NamedColumnIn(wavelength_column, Quantity::kWavelength, d);
  std::vector<double> values = csv.Numbers(value_column, d);
  d.ThrowIfAny();
  TabulatedSpectrum t;
  t.display_name = csv.display_name();
  t.source = csv.source();
  t.quantity = value_column;
  t.wavelength_nm = wl->values;
  t.values = values;
  for (size_t r = 0; r < csv.rows(); ++r) {
    if (r > 0 && !(t.wavelength_nm[r] > t.wavelength_nm[r - 1])) {
      d.Add(csv.LocOfRow(r), fmt::format("column '{}': wavelengths must increase strictly", wavelength_column));
    }
    if (!allow_negative && values[r] < 0.0) {
      d.Add(csv.LocOfRow(r), fmt::format("column '{}': expected a value >= 0, got {}", value_column,
                                         csv.cell(r, csv.ColumnIndex(value_column))));
    } else if (values[r] > max_value) {
      d.Add(csv.LocOfRow(r), fmt::format("column '{}': expected a value from 0 to {}, got {}", value_column,
                                         FormatExact(max_value), csv.cell(r, csv.ColumnIndex(value_column))));
    }
  }
  if (t.wavelength_nm.size() < 2) d.Add(csv.LocOfHeader(), "a spectrum needs at least 2 rows");
  d.ThrowIfAny();
  return t;
}

std::vector<double> TableOnGrid(const SpectralTableRef& ref, const WavelengthGrid& grid, double max_value) {
  CsvTable csv = CsvTable::Load(ref.file);
  if (ref.where) {
    if (csv.ColumnIndex(ref.where->first) < 0) {
      throw InputError(csv.LocOfHeader(), "no column '" + ref.where->first + "' to select rows by");
    }
    csv = csv.Filter(ref.where->first, ref.where->second);
    if (csv.rows() == 0) {
      throw InputError(FileLoc{ref.file.string(), 0},
                       fmt::format("no rows with {} = {}", ref.where->first, ref.where->second));
    }
  }
  return Resample(NamedSpectrum(csv, ref.wavelength_column, ref.value_column, false, max_value), grid).values;
}

}  // namespace skybake
