#include "atmosphere/vertical_profiles.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "atmosphere/ussa1976.h"

namespace skybake {

namespace {
// Boltzmann constant (exact, SI 2019), J/K.
constexpr double kBoltzmann = 1.380649e-23;
// A layer's profile on the grid normalised to a unit column (trapezoid rule); `what` names the
// layer in the error for a profile that is zero everywhere on the grid.
VerticalProfiles::Aerosol LayerShape(const AtmosphereSpec& spec, const std::string& name, const ProfileSpec& profile,
                                     const char* what, const std::vector<double>& z,
                                     std::vector<std::filesystem::path>* inputs_read) {
  VerticalProfiles::Aerosol out;
  out.name = name;
  std::vector<double> raw;
  if (const auto* tb = std::get_if<TableProfile>(&profile)) {
    LoadedTable table = LoadProfileTable(*tb);
    inputs_read->push_back(tb->file);
    raw = SampleShape(*tb, z, &table);
  } else {
    raw = SampleShape(profile, z, nullptr);
  }
  out.raw_column = Trapezoid(z, raw);
  out.raw_peak = raw.empty() ? 0.0 : *std::max_element(raw.begin(), raw.end());
  if (!(out.raw_column > 0.0)) {
    throw InputError(FileLoc{spec.file.string(), 0},
                     std::string(what) + " '" + name + "': the profile is zero everywhere on the altitude grid");
  }
  out.shape_per_m.resize(z.size());
  for (size_t i = 0; i < z.size(); ++i) out.shape_per_m[i] = raw[i] / out.raw_column;
  return out;
}

}  // namespace

VerticalProfiles ComputeProfiles(const AtmosphereSpec& spec) {
  RequireSections(spec, {"planet", "grid", "air"});
  VerticalProfiles p;
  p.altitude_m = spec.AltitudeGrid();
  const std::vector<double>& z = p.altitude_m;
  const size_t n = z.size();

  // Air.
  p.air_number_density_m3.resize(n);
  p.air_temperature_k.resize(n);
  p.air_pressure_pa.resize(n);
  p.air_mass_density_kg_m3.resize(n);
  if (std::holds_alternative<Ussa1976Profile>(spec.air->profile)) {
    for (size_t i = 0; i < n; ++i) {
      ussa1976::State s = ussa1976::AtGeometricAltitude(z[i]);
      p.air_number_density_m3[i] = s.number_density_m3;
      p.air_temperature_k[i] = s.kinetic_temperature_k;
      p.air_pressure_pa[i] = s.pressure_pa;
      p.air_mass_density_kg_m3[i] = s.mass_density_kg_m3;
    }
  } else if (const auto* tb = std::get_if<TableProfile>(&spec.air->profile)) {
    // A measured table (e.g. an AFGL 1986 model): number density and kinetic temperature against
    // altitude; pressure from the ideal-gas law p = n k T, mass density n M0 / NA (dry air).
    LoadedTable density = LoadProfileTable(*tb);
    TableProfile temperature_spec = *tb;
    temperature_spec.value_column = tb->temperature_column;
    temperature_spec.interpolation = Interpolation::kLinear;
    LoadedTable temperature = LoadProfileTable(temperature_spec);
    p.inputs_read.push_back(tb->file);
    Diagnostics d;
    CsvTable csv = CsvTable::Load(tb->file);
    std::optional<CsvTable::SiColumn> nd = csv.NamedColumnIn(tb->value_column, Quantity::kNumberDensity, d);
    std::optional<CsvTable::SiColumn> tk = csv.NamedColumnIn(tb->temperature_column, Quantity::kTemperature, d);
    d.ThrowIfAny();
    for (size_t r = 0; r < csv.rows(); ++r) {
      // Air colder than 100 K or hotter than 400 K is outside every standard atmosphere (AFGL 1986:
      // 184-300 K below 100 km); a density of 0 leaves the Rayleigh sky undefined above it.
      if (!(tk->values[r] >= 100.0 && tk->values[r] <= 400.0)) {
        d.Add(csv.LocOfRow(r), fmt::format("column '{}': expected a temperature from 100 to 400 K, got {}",
                                           tb->temperature_column, csv.cell(r, csv.ColumnIndex(tb->temperature_column))));
      }
      if (!(nd->values[r] > 0.0)) {
        d.Add(csv.LocOfRow(r), fmt::format("column '{}': expected a positive number density, got {}", tb->value_column,
                                           csv.cell(r, csv.ColumnIndex(tb->value_column))));
      }
    }
    d.ThrowIfAny();
    const double unit = UnitScale(Quantity::kNumberDensity, tb->value_column.substr(tb->value_column.rfind('_') + 1)).value_or(1.0);
    std::vector<double> n_raw = SampleShape(*tb, z, &density);
    std::vector<double> t_raw = SampleShape(temperature_spec, z, &temperature);
    for (size_t i = 0; i < n; ++i) {
      const double nd_m3 = n_raw[i] * unit;
      p.air_number_density_m3[i] = nd_m3;
      p.air_temperature_k[i] = t_raw[i];
      p.air_pressure_pa[i] = nd_m3 * kBoltzmann * t_raw[i];
      p.air_mass_density_kg_m3[i] = nd_m3 * ussa1976::kM0 / ussa1976::kNA;
    }
  } else {
    // Exponential air is an isothermal atmosphere: H = R* T / (M0 g0), so T = H M0 g0 / R*.
    const auto& e = std::get<ExponentialProfile>(spec.air->profile);
    const double t = e.scale_height_m * ussa1976::kM0 * ussa1976::kG0 / ussa1976::kRStar;
    std::vector<double> shape = SampleShape(e, z, nullptr);
    for (size_t i = 0; i < n; ++i) {
      const double nd = spec.air->surface_number_density_m3 * shape[i];
      p.air_number_density_m3[i] = nd;
      p.air_temperature_k[i] = t;
      p.air_pressure_pa[i] = nd * kBoltzmann * t;
      p.air_mass_density_kg_m3[i] = nd * ussa1976::kM0 / ussa1976::kNA;
    }
  }

  // Ozone.
  if (spec.ozone) {
    p.has_ozone = true;
    std::vector<double> values;
    if (const auto* tb = std::get_if<TableProfile>(&spec.ozone->profile)) {
      LoadedTable table = LoadProfileTable(*tb);
      p.inputs_read.push_back(tb->file);
      values = SampleShape(*tb, z, &table);
      if (!spec.ozone->column_du) {
        // Absolute table: the value column must be a number density (unit from its name).
        Diagnostics d;
        CsvTable csv = CsvTable::Load(tb->file);
        if (!csv.NamedColumnIn(tb->value_column, Quantity::kNumberDensity, d)) d.ThrowIfAny();
        std::string suffix = tb->value_column.substr(tb->value_column.rfind('_') + 1);
        double scale = UnitScale(Quantity::kNumberDensity, suffix).value_or(1.0);
        for (double& v : values) v *= scale;
      }
    } else {
      values = SampleShape(spec.ozone->profile, z, nullptr);
    }
    double column = Trapezoid(z, values);
    if (spec.ozone->column_du) {
      const double target = *spec.ozone->column_du * kDobsonUnitM2;
      if (column <= 0.0 && target > 0.0) {
        throw InputError(FileLoc{spec.file.string(), 0},
                         "ozone: the profile is zero everywhere on the altitude grid, cannot scale it to a column");
      }
      const double k = column > 0.0 ? target / column : 0.0;
      for (double& v : values) v *= k;
      column = target;
    }
    p.ozone_number_density_m3 = std::move(values);
    p.ozone_column_du = column / kDobsonUnitM2;
  }

  // Aerosol and absorbing-layer shapes.
  for (const AerosolLayerSpec& a : spec.aerosols) {
    p.aerosols.push_back(LayerShape(spec, a.name, a.profile, "aerosol layer", z, &p.inputs_read));
  }
  for (const AbsorberSpec& a : spec.absorbers) {
    p.absorbers.push_back(LayerShape(spec, a.name, a.profile, "absorbing layer", z, &p.inputs_read));
  }
  return p;
}

ExrTable ProfilesToTable(const VerticalProfiles& p) {
  ExrTable t;
  t.axes.push_back({"altitude", "m", "geometric altitude above the ground (planet surface)", p.altitude_m});
  std::vector<const std::vector<double>*> cols;
  auto add = [&](const std::string& name, const std::string& unit, const std::vector<double>& v) {
    t.channels.push_back(name);
    t.channel_units.push_back(unit);
    cols.push_back(&v);
  };
  add("air.number_density", "m^-3", p.air_number_density_m3);
  add("air.temperature", "K", p.air_temperature_k);
  add("air.pressure", "Pa", p.air_pressure_pa);
  add("air.mass_density", "kg m^-3", p.air_mass_density_kg_m3);
  if (p.has_ozone) add("ozone.number_density", "m^-3", p.ozone_number_density_m3);
  for (const auto& a : p.aerosols) add("aerosol." + a.name + ".shape", "m^-1", a.shape_per_m);
  for (const auto& a : p.absorbers) add("absorber." + a.name + ".shape", "m^-1", a.shape_per_m);
  const size_t n = p.altitude_m.size();
  t.values.resize(n * cols.size());
  for (size_t i = 0; i < n; ++i) {
    for (size_t c = 0; c < cols.size(); ++c) t.values[i * cols.size() + c] = static_cast<float>((*cols[c])[i]);
  }
  return t;
}

VerticalProfiles ProfilesFromTable(const ExrTable& t, const std::string& name) {
  if (t.axes.size() != 1 || t.axes[0].name != "altitude" || t.axes[0].unit != "m") {
    throw InputError(FileLoc{name, 0}, "not a profiles table (expected one axis 'altitude' in m)");
  }
  VerticalProfiles p;
  p.altitude_m = t.axes[0].values;
  const size_t n = p.altitude_m.size();
  auto column = [&](const std::string& ch) {
    int c = t.ChannelIndex(ch);
    if (c < 0) throw InputError(FileLoc{name, 0}, "missing channel '" + ch + "'");
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = t.At(i, static_cast<size_t>(c));
    return v;
  };
  p.air_number_density_m3 = column("air.number_density");
  p.air_temperature_k = column("air.temperature");
  p.air_pressure_pa = column("air.pressure");
  p.air_mass_density_kg_m3 = column("air.mass_density");
  if (t.ChannelIndex("ozone.number_density") >= 0) {
    p.has_ozone = true;
    p.ozone_number_density_m3 = column("ozone.number_density");
    p.ozone_column_du = Trapezoid(p.altitude_m, p.ozone_number_density_m3) / kDobsonUnitM2;
  }
  for (const std::string& ch : t.channels) {
    const std::string post = ".shape";
    for (auto [pre, list] : {std::pair{std::string("aerosol."), &p.aerosols}, std::pair{std::string("absorber."), &p.absorbers}}) {
      if (ch.size() > pre.size() + post.size() && ch.compare(0, pre.size(), pre) == 0 &&
          ch.compare(ch.size() - post.size(), post.size(), post) == 0) {
        VerticalProfiles::Aerosol a;
        a.name = ch.substr(pre.size(), ch.size() - pre.size() - post.size());
        a.shape_per_m = column(ch);
        list->push_back(std::move(a));
      }
    }
  }
  return p;
}

}  // namespace skybake
