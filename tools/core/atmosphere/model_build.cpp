#include "atmosphere/model_build.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "io/csv.h"
#include "io/yaml.h"
#include "atmosphere/parametric_optics.h"
#include "atmosphere/table_on_grid.h"
#include "optics/rayleigh.h"
#include "spectrum/solar.h"
#include "spectrum/spectrum.h"

namespace skybake {

namespace {

// Bogumil et al. (2003) ozone cross-section fit coefficients bin-averaged on the grid:
// sigma(T) = (C0 + C1 dT + C2 dT^2) 1e-20 cm^2, dT = T - 273.15 K.
struct OzoneFit {
  std::vector<double> c0, c1, c2;  // m^2, m^2/K, m^2/K^2
};

OzoneFit LoadBogumil(const std::filesystem::path& file, const WavelengthGrid& grid) {
  CsvTable csv = CsvTable::Load(file);
  auto find = [&](const std::string& prefix) {
    for (const std::string& c : csv.columns()) {
      if (c.rfind(prefix, 0) == 0) return c;
    }
    throw InputError(csv.LocOfHeader(), "no column starting with '" + prefix + "' (expected the Bogumil 2003 fit columns)");
  };
  const std::string wl = find("wavelength"), c0 = find("C0_"), c1 = find("C1_"), c2 = find("C2_");
  OzoneFit fit;
  for (auto [col, out] : {std::pair{c0, &fit.c0}, std::pair{c1, &fit.c1}, std::pair{c2, &fit.c2}}) {
    // C1 and C2 may be negative. Bin averages over each grid bin; the table (360-830 nm) ends
    // inside the first and last bins of a 360-830 nm grid, so those bins average over their
    // covered part (the cross-section is smooth there at the bin scale).
    TabulatedSpectrum t = NamedSpectrum(csv, wl, col, true);
    out->resize(grid.size());
    for (size_t i = 0; i < grid.size(); ++i) {
      const double lo = std::max(grid.bin_lo_nm(i), t.wavelength_nm.front());
      const double hi = std::min(grid.bin_hi_nm(i), t.wavelength_nm.back());
      if (!(hi > lo)) {
        throw InputError(FileLoc{file.string(), 0},
                         fmt::format("the table covers {}-{} nm, the wavelength grid needs {} nm", t.wavelength_nm.front(),
                                     t.wavelength_nm.back(), grid[i]));
      }
      (*out)[i] = t.Integral(lo, hi) / (hi - lo) * 1e-20 * 1e-4;  // 1e-20 cm^2 -> m^2
    }
  }
  return fit;
}

// A parametric aerosol layer: extinction at the profile's peak, k_ext(z) = k_ext,peak
// shape(z) / max shape, split by the single-scattering albedo.
MediumComponent ParametricAerosol(const AerosolLayerSpec& layer, const VerticalProfiles& profiles,
                                  const WavelengthGrid& grid, std::vector<std::filesystem::path>* files_read) {
  auto sh = std::find_if(profiles.aerosols.begin(), profiles.aerosols.end(),
                         [&](const VerticalProfiles::Aerosol& a) { return a.name == layer.name; });
  if (sh == profiles.aerosols.end()) {
    throw InputError(layer.optics->extinction.where, "aerosol layer '" + layer.name + "': not in the profiles table");
  }
  const size_t nl = profiles.altitude_m.size(), nw = grid.size();
  const std::vector<double> ext = CoefficientOnGrid(layer.optics->extinction, grid, files_read);
  const std::vector<double> ssa = AlbedoOnGrid(layer.optics->single_scattering_albedo, grid, files_read);
  const double peak = *std::max_element(sh->shape_per_m.begin(), sh->shape_per_m.end());
  MediumComponent c;
  c.name = "aerosol." + layer.name;
  c.phase = PhaseOnGrid(layer.optics->phase, grid, files_read);
  c.scattering.resize(nl * nw);
  c.absorption.resize(nl * nw);
  for (size_t i = 0; i < nl; ++i) {
    const double f = peak > 0.0 ? sh->shape_per_m[i] / peak : 0.0;
    for (size_t w = 0; w < nw; ++w) {
      c.scattering[i * nw + w] = ext[w] * ssa[w] * f;
      c.absorption[i * nw + w] = ext[w] * (1.0 - ssa[w]) * f;
    }
  }
  return c;
}

}  // namespace

std::vector<std::array<double, 6>> LoadLimbDarkening(const std::filesystem::path& file, const WavelengthGrid& grid) {
  CsvTable csv = CsvTable::Load(file);
  Diagnostics d;
  std::vector<double> wl = csv.Numbers("wavelength_nm", d);
  std::array<std::vector<double>, 6> a;
  for (int k = 0; k < 6; ++k) a[static_cast<size_t>(k)] = csv.Numbers(fmt::format("a{}", k), d);
  d.ThrowIfAny();
  for (size_t i = 1; i < wl.size(); ++i) {
    if (!(wl[i] > wl[i - 1])) throw InputError(csv.LocOfRow(i), "wavelengths must increase strictly");
  }
  std::vector<std::array<double, 6>> out;
  for (size_t i = 0; i < grid.size(); ++i) {
    const double w = grid[i];
    if (w < wl.front() || w > wl.back()) {
      throw InputError(FileLoc{file.string(), 0},
                       fmt::format("limb-darkening table covers {}-{} nm, the grid needs {} nm", wl.front(), wl.back(), w));
    }
    size_t j = static_cast<size_t>(std::upper_bound(wl.begin(), wl.end(), w) - wl.begin());
    j = std::clamp<size_t>(j, 1, wl.size() - 1);
    const double t = (w - wl[j - 1]) / (wl[j] - wl[j - 1]);
    std::array<double, 6> c{};
    double sum = 0.0;
    for (size_t k = 0; k < 6; ++k) {
      c[k] = a[k][j - 1] + (a[k][j] - a[k][j - 1]) * t;
      sum += c[k];
    }
    for (double& v : c) v /= sum;
    out.push_back(c);
  }
  return out;
}

AtmosphereModel BuildAtmosphereModel(const AtmosphereSpec& spec, const VerticalProfiles& profiles,
                                     const WavelengthGrid& grid, const std::vector<AerosolOptics>& aerosols,
                                     const ModelOptions& options, std::vector<std::filesystem::path>* files_read) {
  RequireSections(spec, {"planet", "air", "ground", "sun"});
  const size_t nl = profiles.altitude_m.size(), nw = grid.size();
  if (std::abs(profiles.altitude_m.back() - spec.planet->top_m) > 1e-6 * spec.planet->top_m) {
    throw InputError(FileLoc{spec.file.string(), 0},
                     fmt::format("the profiles reach {} m but planet.top_km is {} km", profiles.altitude_m.back(),
                                 spec.planet->top_m / 1e3));
  }
  AtmosphereModel m;
  m.bottom_radius_m = spec.planet->radius_m;
  m.top_radius_m = spec.planet->radius_m + spec.planet->top_m;
  m.altitude_m = profiles.altitude_m;
  m.wavelength_nm = grid.wavelength_nm();

  // Air: Rayleigh, measured (Bodhaine's cross-section per molecule) or parametric (a coefficient
  // at the ground scaled by n(z) / n(0)).
  {
    MediumComponent c;
    c.name = "rayleigh";
    std::vector<double> gamma(nw), sigma(nw);
    if (spec.air->scattering) {
      const double n0 = profiles.air_number_density_m3.front();
      if (!(n0 > 0.0)) throw InputError(FileLoc{spec.file.string(), 0}, "air: the number density at the ground is 0");
      std::vector<double> beta0 = CoefficientOnGrid(*spec.air->scattering, grid, files_read);
      // Chandrasekhar's depolarised phase: gamma = rho_n / (2 - rho_n) (optics/rayleigh.h).
      const double g = spec.air->depolarization / (2.0 - spec.air->depolarization);
      for (size_t w = 0; w < nw; ++w) {
        sigma[w] = beta0[w] / n0;
        gamma[w] = g;
      }
    } else {
      for (size_t w = 0; w < nw; ++w) {
        sigma[w] = rayleigh::CrossSectionM2(grid[w], spec.air->co2_ppm);
        gamma[w] = rayleigh::PhaseGamma(grid[w], spec.air->co2_ppm);
      }
    }
    c.phase = std::make_shared<RayleighPhase>(gamma);
    c.scattering.resize(nl * nw);
    c.absorption.assign(nl * nw, 0.0);
    for (size_t i = 0; i < nl; ++i) {
      for (size_t w = 0; w < nw; ++w) c.scattering[i * nw + w] = profiles.air_number_density_m3[i] * sigma[w];
    }
    m.components.push_back(std::move(c));
  }

  // Ozone: absorption.
  if (options.ozone && spec.ozone && profiles.has_ozone) {
    if (!spec.ozone->cross_section) {
      throw InputError(FileLoc{spec.file.string(), 0}, "ozone: missing 'cross_section' (needed to render)");
    }
    const OzoneCrossSectionSpec& xs = *spec.ozone->cross_section;
    MediumComponent c;
    c.name = "ozone";
    c.scattering.assign(nl * nw, 0.0);
    c.absorption.resize(nl * nw);
    if (xs.kind == OzoneCrossSectionSpec::Kind::kTable) {
      std::vector<double> sigma = TableOnGrid(xs.table, grid);
      if (files_read) files_read->push_back(xs.table.file);
      const std::string& col = xs.table.value_column;
      const double unit = col.size() > 4 && col.compare(col.size() - 4, 4, "_cm2") == 0 ? 1e-4 : 1.0;
      for (size_t i = 0; i < nl; ++i) {
        for (size_t w = 0; w < nw; ++w) c.absorption[i * nw + w] = profiles.ozone_number_density_m3[i] * sigma[w] * unit;
      }
    } else {
      OzoneFit fit = LoadBogumil(xs.bogumil_file, grid);
      if (files_read) files_read->push_back(xs.bogumil_file);
      for (size_t i = 0; i < nl; ++i) {
        // The fit is valid for 203-293 K (Bogumil et al. 2003): clamp the local temperature.
        const double t = xs.temperature_k.value_or(std::clamp(profiles.air_temperature_k[i], 203.0, 293.0));
        const double dt = t - 273.15;
        for (size_t w = 0; w < nw; ++w) {
          const double sigma = std::max(0.0, fit.c0[w] + fit.c1[w] * dt + fit.c2[w] * dt * dt);
          c.absorption[i * nw + w] = profiles.ozone_number_density_m3[i] * sigma;
        }
      }
    }
    m.components.push_back(std::move(c));
  }

  // Aerosols.
  if (options.aerosols) {
    for (const AerosolLayerSpec& layer : spec.aerosols) {
      if (layer.optics) {
        m.components.push_back(ParametricAerosol(layer, profiles, grid, files_read));
        continue;
      }
      auto it = std::find_if(aerosols.begin(), aerosols.end(), [&](const AerosolOptics& a) { return a.layer == layer.name; });
      if (it == aerosols.end()) {
        throw InputError(FileLoc{spec.file.string(), 0}, "aerosol layer '" + layer.name + "': no Mie table was given for it");
      }
      auto sh = std::find_if(profiles.aerosols.begin(), profiles.aerosols.end(),
                             [&](const VerticalProfiles::Aerosol& a) { return a.name == layer.name; });
      if (sh == profiles.aerosols.end()) {
        throw InputError(FileLoc{spec.file.string(), 0}, "aerosol layer '" + layer.name + "': not in the profiles table");
      }
      if (!layer.scale) {
        throw InputError(FileLoc{spec.file.string(), 0}, "aerosol layer '" + layer.name + "': missing 'scale'");
      }
      double column = 0.0;  // particles per m^2
      if (layer.scale->kind == AerosolScale::Kind::kOpticalDepth550nm) {
        column = layer.scale->value / it->cext_550nm_m2;
      } else {
        const double peak = *std::max_element(sh->shape_per_m.begin(), sh->shape_per_m.end());
        column = layer.scale->value / peak;
      }
      MediumComponent c;
      c.name = "aerosol." + layer.name;
      c.phase = it->phase;
      c.scattering.resize(nl * nw);
      c.absorption.resize(nl * nw);
      for (size_t i = 0; i < nl; ++i) {
        const double n = column * sh->shape_per_m[i];
        for (size_t w = 0; w < nw; ++w) {
          c.scattering[i * nw + w] = n * it->csca_m2[w];
          c.absorption[i * nw + w] = n * std::max(0.0, it->cext_m2[w] - it->csca_m2[w]);
        }
      }
      m.components.push_back(std::move(c));
    }
  }

  // Absorbing layers (part of the ozone-like absorption the options switch off with ozone: both
  // are the stratospheric absorbers of the peers' models).
  if (options.ozone) {
    for (const AbsorberSpec& layer : spec.absorbers) {
      auto sh = std::find_if(profiles.absorbers.begin(), profiles.absorbers.end(),
                             [&](const VerticalProfiles::Aerosol& a) { return a.name == layer.name; });
      if (sh == profiles.absorbers.end()) {
        throw InputError(FileLoc{spec.file.string(), 0}, "absorbing layer '" + layer.name + "': not in the profiles table");
      }
      const std::vector<double> k = CoefficientOnGrid(layer.absorption, grid, files_read);
      const double peak = *std::max_element(sh->shape_per_m.begin(), sh->shape_per_m.end());
      MediumComponent c;
      c.name = "absorber." + layer.name;
      c.scattering.assign(nl * nw, 0.0);
      c.absorption.resize(nl * nw);
      for (size_t i = 0; i < nl; ++i) {
        const double f = peak > 0.0 ? sh->shape_per_m[i] / peak : 0.0;
        for (size_t w = 0; w < nw; ++w) c.absorption[i * nw + w] = k[w] * f;
      }
      m.components.push_back(std::move(c));
    }
  }

  // Ground.
  if (spec.ground->albedo_table) {
    m.ground_albedo = TableOnGrid(*spec.ground->albedo_table, grid, 1.0);  // a reflectance: [0, 1]
    if (files_read) files_read->push_back(spec.ground->albedo_table->file);
  } else {
    m.ground_albedo.assign(nw, spec.ground->albedo.value_or(0.0));
  }
  for (double a : m.ground_albedo) {
    if (a < 0.0 || a > 1.0) throw InputError(FileLoc{spec.file.string(), 0}, "ground albedo outside [0, 1] on the grid");
  }

  // Sun.
  if (spec.sun->constant_w_m2_nm) {
    m.sun.irradiance.assign(nw, *spec.sun->constant_w_m2_nm);
  } else {
    m.sun.irradiance = TableOnGrid(spec.sun->spectrum, grid);
    if (files_read) files_read->push_back(spec.sun->spectrum.file);
  }
  m.sun.angular_radius_rad = spec.sun->angular_diameter_deg / 2.0 * std::numbers::pi / 180.0;
  if (spec.sun->limb_darkening_file) {
    m.sun.limb_coefficients = LoadLimbDarkening(*spec.sun->limb_darkening_file, grid);
    if (files_read) files_read->push_back(*spec.sun->limb_darkening_file);
  }
  m.Finalize();
  return m;
}

}  // namespace skybake
