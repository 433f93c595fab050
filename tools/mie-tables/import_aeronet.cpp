#include "import_aeronet.h"

#include <fmt/format.h>

#include <filesystem>
#include <vector>

#include "io/yaml.h"

namespace skybake::mietool {

ImportedType ImportAeronet(const mie::AeronetRetrieval& r, const std::string& name, const std::string& csv_name) {
  const std::string file = std::filesystem::path(r.file).filename().string();
  const std::string where = fmt::format("AERONET Version 2 {} almucantar inversion, {}, {} {} UTC ({} line {})",
                                        r.level, r.site, r.date, r.time, file, r.line);
  ImportedType out;
  // The size table: the 22 radii and dV/d ln r as retrieved.
  out.size_csv = "# source: " + where + "; dV/dlnr in um^3/um^2 (AERONET units) at the retrieval's 22 radii\n";
  out.size_csv += "radius_um,dV_dlnr_um3_um2\n";
  for (size_t i = 0; i < r.radius_um.size(); ++i) {
    out.size_csv += FormatExact(r.radius_um[i]) + "," + FormatExact(r.dv_dlnr_um3_um2[i]) + "\n";
  }
  std::vector<std::string> wl, n, k;
  for (size_t i = 0; i < r.index_wavelength_nm.size(); ++i) {
    wl.push_back(FormatExact(r.index_wavelength_nm[i]));
    n.push_back(FormatExact(r.n[i]));
    k.push_back(FormatExact(r.k[i]));
  }
  out.particle_yaml = fmt::format(
      "# {}: the aerosol of one AERONET retrieval (written by mie-tables import-aeronet).\n"
      "# Source: {}; {} % of the particles spherical.\n"
      "# Size distribution: the retrieval's dV/dlnr at its 22 radii ({}), linear in ln r between them\n"
      "# (optics/size_table.h). Refractive index: its REFR/REFI at {} nm, the end values held outside\n"
      "# them (extrapolation: nearest; docs/mie.md, \"Refractive index from a few wavelengths\").\n"
      "modes:\n"
      "  - name: retrieved\n"
      "    refractive_index:\n"
      "      points: {{wavelength_nm: [{}], n: [{}], k: [{}]}}\n"
      "      extrapolation: nearest\n"
      "    size_table: {}\n"
      "    weight: {{relative_volume: 1.0}}\n",
      name, where, FormatExact(r.sphericity_percent), csv_name, fmt::join(wl, ", "), fmt::join(wl, ", "),
      fmt::join(n, ", "), fmt::join(k, ", "), csv_name);
  out.layer_yaml = fmt::format(
      "# The aerosol-layer scale of {}: the optical depth at 550 nm from the retrieval's extinction\n"
      "# optical depth {} at {} nm and its Angstrom exponent 440-870 nm {}, tau(550) = tau({}) (550/{})^-alpha\n"
      "# ({}). Put it under the layer of an atmosphere's aerosols[] whose particle is {}.yaml.\n"
      "scale: {{optical_depth_550nm: {:.6g}}}\n",
      name, FormatExact(r.aod), FormatExact(r.aod_wavelength_nm), FormatExact(r.angstrom_440_870),
      FormatExact(r.aod_wavelength_nm), FormatExact(r.aod_wavelength_nm), where, name, r.AodAt550());
  return out;
}

}  // namespace skybake::mietool
