#include "optics/aeronet_inversion.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "io/fileio.h"
#include "io/yaml.h"

namespace skybake::mie {

namespace {

// AERONET's 22 radii span 0.05-15 um (Dubovik & King 2000).
constexpr size_t kBins = 22;
constexpr double kFirstRadiusUm = 0.05, kLastRadiusUm = 15.0;

std::vector<std::string> SplitCommas(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// The whole string as a finite number, or nullopt.
std::optional<double> ParseNumber(const std::string& s) {
  if (s.empty()) return std::nullopt;
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

// "<prefix><number><suffix>" -> the number.
std::optional<double> NumberBetween(const std::string& name, const std::string& prefix, const std::string& suffix) {
  if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return std::nullopt;
  }
  return ParseNumber(name.substr(prefix.size(), name.size() - prefix.size() - suffix.size()));
}

struct Columns {
  std::vector<std::pair<double, int>> radii;        // radius um, column
  std::map<double, int> refr, refi;                  // wavelength nm -> column
  std::optional<std::pair<double, int>> aod;         // wavelength, column
  int angstrom = -1, sphericity = -1, date = -1, time = -1;
};

Columns FindColumns(const std::vector<std::string>& names, const FileLoc& header) {
  Columns c;
  for (int i = 0; i < static_cast<int>(names.size()); ++i) {
    const std::string& name = names[i];
    if (std::optional<double> r = ParseNumber(name)) {
      c.radii.emplace_back(*r, i);
    } else if (std::optional<double> wl = NumberBetween(name, "REFR(", ")")) {
      c.refr[*wl] = i;
    } else if (std::optional<double> wl2 = NumberBetween(name, "REFI(", ")")) {
      c.refi[*wl2] = i;
    } else if (std::optional<double> wl3 = NumberBetween(name, "AOTExt", "-T")) {
      if (*wl3 >= 430.0 && *wl3 <= 450.0 && !c.aod) c.aod = std::make_pair(*wl3, i);
    } else if (name == "870-440AngstromParam.[AOTExt]-Total") {
      c.angstrom = i;
    } else if (name == "%sphericity") {
      c.sphericity = i;
    } else if (name == "Date(dd-mm-yyyy)") {
      c.date = i;
    } else if (name == "Time(hh:mm:ss)") {
      c.time = i;
    }
  }
  Diagnostics d;
  if (c.radii.size() != kBins) {
    d.Add(header, fmt::format("expected the {} size-distribution columns 0.050000 ... 15.000000 (radius in um), "
                              "found {}", kBins, c.radii.size()));
  } else {
    for (size_t i = 1; i < kBins; ++i) {
      if (!(c.radii[i].first > c.radii[i - 1].first)) {
        d.Add(header, fmt::format("size-distribution columns: radii must increase ({} after {})",
                                  names[c.radii[i].second], names[c.radii[i - 1].second]));
      }
    }
    if (std::abs(c.radii.front().first - kFirstRadiusUm) > 1e-6 || std::abs(c.radii.back().first - kLastRadiusUm) > 1e-6) {
      d.Add(header, fmt::format("size-distribution columns span {}-{} um, expected AERONET's 0.05-15 um",
                                names[c.radii.front().second], names[c.radii.back().second]));
    }
  }
  std::vector<double> wl_r, wl_i;
  for (const auto& [wl, col] : c.refr) wl_r.push_back(wl);
  for (const auto& [wl, col] : c.refi) wl_i.push_back(wl);
  if (wl_r.size() < 2 || wl_r != wl_i) {
    d.Add(header, fmt::format("expected REFR(<nm>) and REFI(<nm>) columns at the same 2 or more wavelengths, found "
                              "REFR at [{}] nm and REFI at [{}] nm",
                              fmt::join(wl_r, ", "), fmt::join(wl_i, ", ")));
  }
  if (!c.aod) d.Add(header, "missing column AOTExt<nm>-T with <nm> from 430 to 450 (e.g. AOTExt441-T)");
  if (c.angstrom < 0) d.Add(header, "missing column 870-440AngstromParam.[AOTExt]-Total");
  if (c.sphericity < 0) d.Add(header, "missing column %sphericity");
  if (c.date < 0) d.Add(header, "missing column Date(dd-mm-yyyy)");
  if (c.time < 0) d.Add(header, "missing column Time(hh:mm:ss)");
  d.ThrowIfAny();
  return c;
}

}  // namespace

double AeronetRetrieval::AodAt550() const { return aod * std::pow(550.0 / aod_wavelength_nm, -angstrom_440_870); }

AeronetRetrieval ReadAeronetRetrieval(const std::filesystem::path& path, const AeronetReadOptions& options) {
  const std::string display = path.string();
  std::vector<std::string> lines;
  {
    std::istringstream in(ReadFileBytes(path));
    std::string l;
    while (std::getline(in, l)) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      lines.push_back(l);
    }
  }
  auto at = [&](int line) { return FileLoc{display, line}; };
  if (lines.size() < 4) {
    throw InputError(at(static_cast<int>(lines.size())),
                     "expected AERONET's 3 header lines and a line of column names (docs/mie.md, "
                     "\"Importing an AERONET inversion\")");
  }
  AeronetRetrieval r;
  r.file = display;
  // Line 1: the site; line 2: the level.
  const std::vector<std::string> first = SplitCommas(lines[0]);
  for (const std::string& f : first) {
    if (f.rfind("Locations=", 0) == 0) r.site = f.substr(10);
  }
  if (r.site.empty()) throw InputError(at(1), "expected the site line 'dd:mm:yyyy,Locations=<site>,...'");
  if (lines[1].find("Almucantar Retrievals") == std::string::npos ||
      (lines[1].rfind("Level 1.5", 0) != 0 && lines[1].rfind("Level 2.0", 0) != 0)) {
    throw InputError(at(2), "expected 'Level 1.5 Almucantar Retrievals, Version 2' or 'Level 2.0 ...', got '" +
                                lines[1] + "'");
  }
  r.level = lines[1].substr(0, 9);
  const std::vector<std::string> names = SplitCommas(lines[3]);
  const Columns c = FindColumns(names, at(4));

  // The retrieval's line.
  std::vector<int> rows;
  for (size_t i = 4; i < lines.size(); ++i) {
    if (!lines[i].empty()) rows.push_back(static_cast<int>(i) + 1);
  }
  if (rows.empty()) throw InputError(at(4), "no retrieval follows the column names");
  if (!options.row && rows.size() > 1) {
    throw UsageError(fmt::format("--row: {} holds {} retrievals (lines {}-{}); choose one with --row 1..{}", display,
                                 rows.size(), rows.front(), rows.back(), rows.size()));
  }
  const int row = options.row.value_or(1);
  if (row < 1 || row > static_cast<int>(rows.size())) {
    throw UsageError(fmt::format("--row {}: {} holds {} retrieval(s)", row, display, rows.size()));
  }
  r.line = rows[row - 1];
  const std::vector<std::string> cells = SplitCommas(lines[r.line - 1]);
  if (cells.size() != names.size()) {
    throw InputError(at(r.line), fmt::format("expected {} cells (the column names of line 4), got {}", names.size(),
                                             cells.size()));
  }
  Diagnostics d;
  auto value = [&](int col) {
    const std::string& s = cells[col];
    std::optional<double> v = ParseNumber(s);
    if (!v || *v == -999.0) {
      d.Add(at(r.line), fmt::format("column '{}': {}", names[col],
                                    v ? "-999, AERONET's fill value: this retrieval has no such value"
                                      : "expected a number, got '" + s + "'"));
      return 0.0;
    }
    return *v;
  };
  for (const auto& [radius, col] : c.radii) {
    r.radius_um.push_back(radius);
    const double v = value(col);
    if (v < 0.0 && v != -999.0) d.Add(at(r.line), fmt::format("column '{}': dV/dlnr must be >= 0, got {}", names[col], cells[col]));
    r.dv_dlnr_um3_um2.push_back(v);
  }
  for (const auto& [wl, col] : c.refr) {
    r.index_wavelength_nm.push_back(wl);
    r.n.push_back(value(col));
    r.k.push_back(value(c.refi.at(wl)));
  }
  r.aod_wavelength_nm = c.aod->first;
  r.aod = value(c.aod->second);
  r.angstrom_440_870 = value(c.angstrom);
  r.sphericity_percent = value(c.sphericity);
  r.date = cells[c.date];
  r.time = cells[c.time];
  d.ThrowIfAny();
  if (r.sphericity_percent < options.min_sphericity_percent) {
    throw InputError(at(r.line),
                     fmt::format("column '%sphericity': {} % of the particles are spherical, below {} %: the retrieval "
                                 "models the rest as spheroids, which Mie spheres do not represent",
                                 cells[c.sphericity], FormatExact(options.min_sphericity_percent)));
  }
  if (!(r.aod > 0.0)) {
    throw InputError(at(r.line), fmt::format("column '{}': the optical depth must be > 0, got {}", names[c.aod->second],
                                             cells[c.aod->second]));
  }
  return r;
}

}  // namespace skybake::mie
