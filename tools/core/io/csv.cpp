#include "io/csv.h"
#include "io/fileio.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

namespace skybake {

namespace {

struct UnitEntry {
  Quantity q;
  const char* suffix;
  double scale;  // multiply the column value by this to get SI
};

// Unit suffixes understood in column names. Scales are exact definitions of the units.
const UnitEntry kUnits[] = {
    {Quantity::kLength, "m", 1.0},
    {Quantity::kLength, "km", 1e3},
    {Quantity::kLength, "um", 1e-6},
    {Quantity::kLength, "nm", 1e-9},
    {Quantity::kWavelength, "nm", 1.0},
    {Quantity::kWavelength, "um", 1e3},
    {Quantity::kNumberDensity, "m3", 1.0},
    {Quantity::kNumberDensity, "cm3", 1e6},
    {Quantity::kInverseLength, "per_m", 1.0},
    {Quantity::kInverseLength, "per_km", 1e-3},
    {Quantity::kInverseLength, "m-1", 1.0},
    {Quantity::kInverseLength, "km-1", 1e-3},
    {Quantity::kCrossSection, "m2", 1.0},
    {Quantity::kCrossSection, "cm2", 1e-4},
    {Quantity::kCrossSection, "um2", 1e-12},
    {Quantity::kTemperature, "K", 1.0},
    {Quantity::kPressure, "Pa", 1.0},
    {Quantity::kPressure, "hPa", 100.0},
    {Quantity::kPressure, "mb", 100.0},
    {Quantity::kMassDensity, "kg_m3", 1.0},
    {Quantity::kMassDensity, "g_cm3", 1e3},
};

std::string Trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.push_back(Trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(Trim(cur));
  return out;
}

std::optional<double> ParseNumber(const std::string& t) {
  if (t.empty()) return std::nullopt;
  const char* b = t.data();
  if (*b == '+') ++b;
  double v = 0;
  auto res = std::from_chars(b, t.data() + t.size(), v, std::chars_format::general);
  if (res.ec != std::errc() || res.ptr != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

std::optional<double> UnitScale(Quantity q, const std::string& suffix) {
  if (q == Quantity::kDimensionless) return 1.0;
  for (const UnitEntry& u : kUnits) {
    if (u.q == q && suffix == u.suffix) return u.scale;
  }
  return std::nullopt;
}

std::string UnitSuffixes(Quantity q) {
  std::string s;
  for (const UnitEntry& u : kUnits) {
    if (u.q != q) continue;
    if (!s.empty()) s += ", ";
    s += std::string("_") + u.suffix;
  }
  return s;
}

CsvTable CsvTable::Load(const std::filesystem::path& path) {
  return Parse(ReadFileBytes(path), path.string());
}

CsvTable CsvTable::Parse(const std::string& text, const std::string& display_name) {
  CsvTable t;
  t.display_name_ = display_name;
  Diagnostics diags;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  bool saw_source = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::string trimmed = Trim(line);
    if (line_no == 1) {
      const std::string prefix = "# source:";
      if (trimmed.rfind(prefix, 0) != 0 || Trim(trimmed.substr(prefix.size())).empty()) {
        throw InputError(FileLoc{display_name, 1},
                         "the first line must be '# source: <where the data come from>'");
      }
      t.source_ = Trim(trimmed.substr(prefix.size()));
      saw_source = true;
      continue;
    }
    if (trimmed.empty() || trimmed[0] == '#') continue;
    std::vector<std::string> cells = SplitCells(line);
    if (t.columns_.empty()) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i].empty()) diags.Add(FileLoc{display_name, line_no}, fmt::format("header: column {} has no name", i + 1));
        for (size_t j = 0; j < i; ++j) {
          if (cells[i] == cells[j] && !cells[i].empty()) {
            diags.Add(FileLoc{display_name, line_no}, fmt::format("header: duplicate column '{}'", cells[i]));
          }
        }
      }
      t.columns_ = cells;
      t.header_line_ = line_no;
      continue;
    }
    if (cells.size() != t.columns_.size()) {
      diags.Add(FileLoc{display_name, line_no},
                fmt::format("expected {} cells (as in the header on line {}), got {}", t.columns_.size(),
                            t.header_line_, cells.size()));
      continue;
    }
    t.cells_.push_back(std::move(cells));
    t.row_lines_.push_back(line_no);
  }
  if (!saw_source) throw InputError(FileLoc{display_name, 1}, "the file is empty (expected '# source: ...')");
  if (t.columns_.empty()) diags.Add(FileLoc{display_name, line_no}, "no header row");
  else if (t.cells_.empty() && diags.empty()) diags.Add(FileLoc{display_name, t.header_line_}, "no data rows");
  diags.ThrowIfAny();
  return t;
}

int CsvTable::ColumnIndex(const std::string& name) const {
  for (size_t i = 0; i < columns_.size(); ++i) {
    if (columns_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<double> CsvTable::Numbers(const std::string& name, Diagnostics& diags,
                                      bool allow_empty) const {
  std::vector<double> out;
  int c = ColumnIndex(name);
  if (c < 0) {
    diags.Add(LocOfHeader(), fmt::format("no column '{}' (columns: {})", name, fmt::join(columns_, ", ")));
    return out;
  }
  out.reserve(cells_.size());
  for (size_t r = 0; r < cells_.size(); ++r) {
    const std::string& cell = cells_[r][c];
    if (cell.empty()) {
      if (!allow_empty) diags.Add(LocOfRow(r), fmt::format("column '{}': missing value", name));
      out.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    std::optional<double> v = ParseNumber(cell);
    if (!v) {
      diags.Add(LocOfRow(r), fmt::format("column '{}': expected a number, got \"{}\"", name, cell));
      out.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    out.push_back(*v);
  }
  return out;
}

std::optional<CsvTable::SiColumn> CsvTable::NamedColumnIn(const std::string& name, Quantity q,
                                                          Diagnostics& diags, bool allow_empty) const {
  std::optional<double> scale;
  if (q == Quantity::kDimensionless) {
    scale = 1.0;
  } else {
    // The longest known suffix that ends the name wins ("per_km" before "km").
    size_t best_len = 0;
    for (const UnitEntry& u : kUnits) {
      if (u.q != q) continue;
      std::string suf = std::string("_") + u.suffix;
      if (name.size() > suf.size() && name.compare(name.size() - suf.size(), suf.size(), suf) == 0 &&
          suf.size() > best_len) {
        best_len = suf.size();
        scale = u.scale;
      }
    }
  }
  if (!scale) {
    diags.Add(LocOfHeader(), fmt::format("column '{}': the name must end in a unit ({})", name, UnitSuffixes(q)));
    return std::nullopt;
  }
  if (ColumnIndex(name) < 0) {
    diags.Add(LocOfHeader(), fmt::format("no column '{}' (columns: {})", name, fmt::join(columns_, ", ")));
    return std::nullopt;
  }
  SiColumn col{name, Numbers(name, diags, allow_empty)};
  for (double& v : col.values) v *= *scale;
  return col;
}

std::optional<CsvTable::SiColumn> CsvTable::ColumnIn(const std::string& base, Quantity q,
                                                     Diagnostics& diags, bool allow_empty) const {
  for (const std::string& name : columns_) {
    if (name.size() <= base.size() + 1 || name.compare(0, base.size() + 1, base + "_") != 0) continue;
    std::string suffix = name.substr(base.size() + 1);
    if (UnitScale(q, suffix)) return NamedColumnIn(name, q, diags, allow_empty);
  }
  diags.Add(LocOfHeader(), fmt::format("no column '{}_<unit>' with a unit of {} (columns: {})", base,
                                       UnitSuffixes(q), fmt::join(columns_, ", ")));
  return std::nullopt;
}

CsvTable CsvTable::Filter(const std::string& key, const std::string& value) const {
  CsvTable out;
  out.display_name_ = display_name_;
  out.source_ = source_;
  out.columns_ = columns_;
  out.header_line_ = header_line_;
  int c = ColumnIndex(key);
  if (c < 0) return out;
  for (size_t r = 0; r < cells_.size(); ++r) {
    if (cells_[r][c] == value) {
      out.cells_.push_back(cells_[r]);
      out.row_lines_.push_back(row_lines_[r]);
    }
  }
  return out;
}

}  // namespace skybake
