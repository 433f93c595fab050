// The CSV reader (io/csv.h) on arbitrary bytes: every column as numbers and in SI units, row
// filters, and the spectral reader (spectrum/spectrum.h) on every column - the paths of the
// measured tables and of sky-render's points CSV.
#include "fuzz_common.h"
#include "io/csv.h"
#include "spectrum/spectrum.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Guarded([&] {
    CsvTable t = CsvTable::Parse(fuzz::Text(data, size), "fuzz.csv");
    for (const std::string& c : t.columns()) {
      Diagnostics d;
      (void)t.Numbers(c, d, true);
      for (Quantity q : {Quantity::kLength, Quantity::kWavelength, Quantity::kNumberDensity, Quantity::kCrossSection,
                         Quantity::kTemperature, Quantity::kPressure, Quantity::kDimensionless}) {
        (void)t.NamedColumnIn(c, q, d, true);
      }
      fuzz::Guarded([&] { (void)SpectrumColumn(t, c, true); });
      if (t.rows() > 0) (void)t.Filter(c, t.cell(0, 0));
    }
    Diagnostics d;
    (void)t.ColumnIn("wavelength", Quantity::kWavelength, d);
  });
  return 0;
}
