#include "spectrum/cmf.h"

#include <fmt/format.h>

#include "io/csv.h"
#include "io/repo_paths.h"

namespace skybake {

const char* ObserverName(Observer observer) {
  switch (observer) {
    case Observer::kCie2006_2deg: return "cie2006_2deg";
    case Observer::kCie1931_2deg: return "cie1931_2deg";
  }
  return "";
}

std::optional<Observer> ParseObserver(std::string_view name) {
  for (Observer o : {Observer::kCie2006_2deg, Observer::kCie1931_2deg}) {
    if (name == ObserverName(o)) return o;
  }
  return std::nullopt;
}

const char* CmfFileName(Observer observer) {
  switch (observer) {
    case Observer::kCie2006_2deg: return "cie2006_2deg_xyz_cmf_1nm.csv";
    case Observer::kCie1931_2deg: return "cie1931_2deg_xyz_cmf_1nm.csv";
  }
  return "";
}

std::filesystem::path DefaultCmfPath(Observer observer) {
  return FindRepoFile(std::filesystem::path("atmospheres/data") / CmfFileName(observer));
}

Cmf Cmf::Load(const std::filesystem::path& csv_path, Observer observer) {
  CsvTable table = CsvTable::Load(csv_path);
  Cmf cmf;
  cmf.observer_ = observer;
  cmf.path_ = csv_path;
  // Each column is checked on its own; report every problem of the file at once.
  Diagnostics diags;
  const char* names[3] = {"xbar", "ybar", "zbar"};
  for (int c = 0; c < 3; ++c) {
    try {
      cmf.bar_[c] = SpectrumColumn(table, names[c], /*require_non_negative=*/true);
      cmf.bar_[c].zero_outside = true;
    } catch (const InputError& e) {
      for (const Diagnostic& d : e.diagnostics()) {
        bool seen = false;
        for (const Diagnostic& o : diags.items()) seen = seen || (o.loc.line == d.loc.line && o.message == d.message);
        if (!seen) diags.Add(d.loc, d.message);
      }
    }
  }
  diags.ThrowIfAny();
  // Extend each function by one table step with an explicit zero at both ends (389 and 831 nm for
  // CIE 2006; 359 and 831 nm for CIE 1931): the linear interpolant then ramps to zero over that
  // step, and its exact integral equals the plain 1 nm sum Σ c̄(λ_j)·1 nm that the CIE and CVRL
  // tabulate and normalise (CVRL: equal integrals of x̄, ȳ, z̄ at 1 nm, so E is at 1/3, 1/3).
  for (TabulatedSpectrum& t : cmf.bar_) {
    std::vector<double>& x = t.wavelength_nm;
    const double first_step = x[1] - x[0];
    const double last_step = x[x.size() - 1] - x[x.size() - 2];
    x.insert(x.begin(), x.front() - first_step);
    x.push_back(x.back() + last_step);
    t.values.insert(t.values.begin(), 0.0);
    t.values.push_back(0.0);
  }
  return cmf;
}

Cmf Cmf::LoadDefault(Observer observer) { return Load(DefaultCmfPath(observer), observer); }

std::array<double, 3> Cmf::Eval(double wavelength_nm) const {
  return {bar_[0].Eval(wavelength_nm), bar_[1].Eval(wavelength_nm), bar_[2].Eval(wavelength_nm)};
}

std::array<double, 3> Cmf::Integral() const {
  std::array<double, 3> out{};
  for (int c = 0; c < 3; ++c) out[c] = bar_[c].Integral(min_nm(), max_nm());
  return out;
}

std::array<Spectrum, 3> Cmf::OnGrid(const WavelengthGrid& grid) const {
  return {Resample(bar_[0], grid), Resample(bar_[1], grid), Resample(bar_[2], grid)};
}

}  // namespace skybake
