// One retrieval of an AERONET Version 2 almucantar inversion product (Level 1.5 or 2.0,
// "Combined Dubovik Retrievals, ALL POINTS DATA"), as `mie-tables import-aeronet` reads it
// (docs/mie.md, "Importing an AERONET inversion").
//
// Layout (AERONET's Version 2 download files, units at aeronet.gsfc.nasa.gov/new_web/units.html;
// a published example: the Level 2.0 combined file of Chilbolton, 10 October 2005, in
// gist.github.com/robintw/1958483):
//   line 1  dd:mm:yyyy,Locations=<site>,long=..,lat=..,elev=..,Nmeas=..,PI=..,Email=..
//   line 2  Level 2.0 Almucantar Retrievals, Version 2        (or Level 1.5)
//   line 3  Combined Dubovik Retrievals,ALL POINTS DATA,Inversion Product UNITS can be found at,...
//   line 4  the column names: Date(dd-mm-yyyy),Time(hh:mm:ss),...
//   line 5+ one retrieval per line, comma-separated, -999 (or N/A) where a value is missing.
// Columns read (by name, in any order):
//   the 22 size-distribution columns, named by their radius in um (0.050000, 0.065604, ...,
//     15.000000: log-spaced, Dubovik & King 2000, JGR 105, 20673), dV/d ln r in um^3/um^2;
//   REFR(<nm>) and REFI(<nm>): the real and imaginary refractive index at each retrieval
//     wavelength (441, 675, 871, 1020 nm in Version 2 files);
//   AOTExt<nm>-T with <nm> in 430-450: the retrieval's total extinction optical depth near 440 nm;
//   870-440AngstromParam.[AOTExt]-Total: its Angstrom exponent 440-870 nm;
//   %sphericity: the retrieved percentage of spherical particles (the retrieval models the
//     rest as spheroids, Dubovik et al. 2006, JGR 111, D11208);
//   Date(dd-mm-yyyy), Time(hh:mm:ss): named in the written type's source line.
// Problems (a missing column, a fill value in a column read, fewer than 22 radii, a sphericity
// below the threshold) are InputErrors at the file's line.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/error.h"

namespace skybake::mie {

struct AeronetRetrieval {
  std::string file;  // as given (for messages and the source line)
  int line = 0;      // the retrieval's line
  std::string site, level, date, time;
  std::vector<double> radius_um, dv_dlnr_um3_um2;  // the 22 bins
  std::vector<double> index_wavelength_nm, n, k;   // REFR/REFI, ascending wavelength
  double aod_wavelength_nm = 0.0, aod = 0.0;       // AOTExt<nm>-T
  double angstrom_440_870 = 0.0;
  double sphericity_percent = 0.0;

  // The optical depth at 550 nm by the Angstrom law tau(l) = tau(l0) (l / l0)^-alpha from the
  // retrieval's own extinction near 440 nm (Angstrom 1929; alpha the file's 440-870 exponent).
  double AodAt550() const;
};

struct AeronetReadOptions {
  std::optional<int> row;  // 1-based retrieval; required when the file holds more than one
  double min_sphericity_percent = 95.0;
};

// Reads and checks one retrieval; InputError at file:line for bad content, UsageError for a
// --row outside the file or missing where the file holds several retrievals.
AeronetRetrieval ReadAeronetRetrieval(const std::filesystem::path& path, const AeronetReadOptions& options);

}  // namespace skybake::mie
