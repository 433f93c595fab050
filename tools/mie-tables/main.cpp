// mie-tables: aerosol optics from Mie theory (docs/mie.md).
//
//   mie-tables sphere --m 1.33+1e-5i --x 100 [--angles-deg 0,30,60] [-o out.json]
//       one homogeneous sphere: Q_ext, Q_sca, Q_abs, Q_back, g, S1, S2 as JSON
//   mie-tables build TYPE.yaml -o TYPE.exr [--report TYPE.report.json] [--depfile TYPE.exr.d]
//       [--wavelength-min-nm 360 --wavelength-max-nm 830 --wavelength-step-nm 5] [--mode NAME]
//       the Mie table of a particle type (optics/mie_table.h) and its report
//   mie-tables dump TABLE.exr --what spectral|phase [--wavelength-nm 550] [-o out.csv]
//       a table as CSV (for charts and for reading without an EXR library)
//   mie-tables import-aeronet FILE -o NAME.yaml [--row N] [--min-sphericity-percent 95] [--layer L.yaml]
//       a particle type (YAML and size-table CSV) and the aerosol-layer scale of one AERONET
//       almucantar inversion retrieval (optics/aeronet_inversion.h)
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>

#include "io/cli.h"
#include "io/exr.h"
#include "io/fileio.h"
#include "io/yaml.h"
#include "import_aeronet.h"
#include "optics/aeronet_inversion.h"
#include "optics/mie_sphere.h"
#include "optics/mie_table.h"
#include "optics/particle_type.h"
#include "optics/polydisperse.h"
#include "report.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {

// "1.33", "1.33+1e-5i", "1.5+1i", "10+10j": m = n + ik. A negative k is a usage error.
std::complex<double> ParseIndex(const std::string& text) {
  auto bad = [&](const std::string& why) { throw UsageError("--m '" + text + "': " + why); };
  auto number = [&](const std::string& s) {
    size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      bad("expected n or n+ki, e.g. 1.33+1e-5i");
    }
    if (used != s.size() || !std::isfinite(v)) bad("expected n or n+ki, e.g. 1.33+1e-5i");
    return v;
  };
  std::string t;
  for (char c : text) {
    if (c != ' ') t += c;
  }
  if (t.empty()) bad("expected n or n+ki, e.g. 1.33+1e-5i");
  size_t split = std::string::npos;
  for (size_t i = 1; i < t.size(); ++i) {
    if ((t[i] == '+' || t[i] == '-') && t[i - 1] != 'e' && t[i - 1] != 'E') split = i;
  }
  double n = 0.0, k = 0.0;
  if (split == std::string::npos) {
    if (t.back() == 'i' || t.back() == 'j') bad("give the real part too, e.g. 1.5+0.1i");
    n = number(t);
  } else {
    n = number(t.substr(0, split));
    std::string im = t.substr(split);
    if (im.back() != 'i' && im.back() != 'j') bad("the imaginary part must end in i, e.g. 1.33+1e-5i");
    im.pop_back();
    k = (im == "+" || im == "-") ? (im == "+" ? 1.0 : -1.0) : number(im);
  }
  // |m| x bounds the number of series terms (Wiscombe 1980): with n, k <= 10 and x <= 1e5 at
  // most ~1e6 terms, well under a second (docs/mie.md, "sphere").
  if (!(n > 0.0 && n <= 10.0)) bad("the real part must be in (0, 10]");
  if (k > 10.0) bad("the imaginary part must be at most 10");
  if (k < 0.0) {
    bad("the imaginary part must be >= 0: skybake writes m = n + ik with k >= 0 for absorbing media "
        "(MIEV0 and some tables write n - ik)");
  }
  return {n, k};
}

std::vector<double> WavelengthGrid(double min_nm, double max_nm, double step_nm) {
  if (!(max_nm >= min_nm)) throw UsageError("--wavelength-max-nm must not be below --wavelength-min-nm");
  const double n = (max_nm - min_nm) / step_nm;
  if (std::abs(n - std::round(n)) > 1e-9) {
    throw UsageError("(--wavelength-max-nm - --wavelength-min-nm) must be a whole number of --wavelength-step-nm");
  }
  // The same values as pipeline.yaml's grid (tools/skybake/pipeline.cpp, WavelengthGrid::Values).
  std::vector<double> v;
  const size_t count = static_cast<size_t>(std::llround(n));
  for (size_t i = 0; i <= count; ++i) v.push_back(min_nm + static_cast<double>(i) * step_nm);
  return v;
}

// A type's name is its file stem: a lowercase identifier (docs/mie.md, "Valid ranges").
bool IsTypeName(const std::string& s) {
  if (s.empty() || s.size() > 64 || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

void WriteText(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::cout << text;
  } else {
    WriteFileIfChanged(path, text);
  }
}

// import-aeronet: reads and checks the retrieval, then writes the type, its size table and the
// layer scale (all inside the tool's output transaction: nothing is written on an error).
void RunImportAeronet(ToolCli& cli, const std::string& aeronet_file, const std::string& import_out,
                      const std::string& layer_out, int import_row, double min_sphericity) {
  const fs::path out(import_out);
  const std::string name = out.stem().string();
  if (out.extension() != ".yaml" || !IsTypeName(name)) {
    throw UsageError("--output '" + import_out + "': expected NAME.yaml with NAME a lowercase identifier (a-z, 0-9, "
                     "_; starting with a letter): the type is named by its file");
  }
  mie::AeronetReadOptions options;
  if (import_row > 0) options.row = import_row;
  options.min_sphericity_percent = min_sphericity;
  const mie::AeronetRetrieval r = mie::ReadAeronetRetrieval(aeronet_file, options);
  const std::string csv_name = name + "_size_distribution.csv";
  const mietool::ImportedType t = mietool::ImportAeronet(r, name, csv_name);
  WriteFileIfChanged(out, t.particle_yaml);
  WriteFileIfChanged(out.parent_path() / csv_name, t.size_csv);
  WriteFileIfChanged(layer_out.empty() ? out.parent_path() / (name + ".layer.yaml") : fs::path(layer_out), t.layer_yaml);
  cli.Info(fmt::format("wrote {} ({} line {}, {} {}; optical depth {:.4g} at 550 nm)", import_out, aeronet_file,
                       r.line, r.date, r.time, r.AodAt550()));
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("mie-tables",
              "Aerosol optics from Mie theory: single spheres, and per-wavelength tables of cross sections,\n"
              "albedo, asymmetry and phase function (with its CDF and fitted HG / Cornette-Shanks / dual-lobe\n"
              "models) for the modes (log-normal or tabulated) of a particle type, and particle types from AERONET\n"
              "inversions. See docs/mie.md.");
  CLI::App& app = cli.app();
  app.require_subcommand(1);

  // sphere
  CLI::App* sphere = app.add_subcommand("sphere", "One homogeneous sphere, printed as JSON (docs/mie.md, \"sphere\")");
  sphere->fallthrough();
  std::string m_text, sphere_out;
  double x = 0.0;
  std::vector<double> angles_deg;
  sphere->add_option("--m", m_text, "Relative refractive index n+ki (k >= 0 absorbs), e.g. 1.33+1e-5i")->required();
  sphere->add_option("--x", x, "Size parameter 2 pi r / lambda, 1e-6 to 1e5")->required()->check(CLI::Range(1e-6, 1e5));
  sphere->add_option("--angles-deg", angles_deg, "Scattering angles in degrees for S1, S2 (comma-separated)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 180.0));
  sphere->add_option("-o,--output", sphere_out, "Write the JSON here instead of stdout");

  // build
  CLI::App* build = app.add_subcommand("build", "The Mie table of a particle type (EXR) and its report (JSON)");
  build->fallthrough();
  std::string input, output, report_path, depfile, mode_name;
  double wl_min = 360.0, wl_max = 830.0, wl_step = 5.0;
  build->add_option("particle", input, "Particle type YAML (particles/*.yaml or its canonical component)")->required();
  build->add_option("-o,--output", output, "Output Mie table (.exr)")->required();
  build->add_option("--report", report_path, "Report JSON (default: the output with .report.json)");
  build->add_option("--depfile", depfile, "Write a Make-style depfile listing every file read");
  build->add_option("--wavelength-min-nm", wl_min, "First wavelength of the grid, nm (default 360)")
      ->check(CLI::Range(200.0, 3000.0));
  build->add_option("--wavelength-max-nm", wl_max, "Last wavelength of the grid, nm (default 830)")
      ->check(CLI::Range(200.0, 3000.0));
  build->add_option("--wavelength-step-nm", wl_step, "Grid step, nm (default 5)")->check(CLI::PositiveNumber);
  build->add_option("--mode", mode_name, "Only this mode of the type (e.g. for charts of one mode)");

  // dump
  CLI::App* dump = app.add_subcommand("dump", "A Mie table as CSV");
  dump->fallthrough();
  std::string table_path, what = "spectral", dump_out;
  double dump_wl = -1.0;
  dump->add_option("table", table_path, "Mie table (.exr) written by 'mie-tables build'")->required();
  dump->add_option("--what", what, "spectral: one row per wavelength; phase: one row per angle at --wavelength-nm")
      ->check(CLI::IsMember({"spectral", "phase"}));
  dump->add_option("--wavelength-nm", dump_wl, "Tabulated wavelength for --what phase, nm");
  dump->add_option("-o,--output", dump_out, "Output CSV (default: stdout)");

  // import-aeronet
  CLI::App* import_cmd = app.add_subcommand("import-aeronet", "A particle type and layer scale from an AERONET inversion");
  import_cmd->fallthrough();
  std::string aeronet_file, import_out, layer_out;
  int import_row = 0;
  double min_sphericity = 95.0;
  import_cmd->add_option("file", aeronet_file, "AERONET Version 2 almucantar inversion (Level 1.5/2.0, all points, CSV)")
      ->required();
  import_cmd->add_option("-o,--output", import_out, "Particle type to write, NAME.yaml (NAME_size_distribution.csv beside it)")
      ->required();
  import_cmd->add_option("--row", import_row, "Retrieval to import, 1 = the first line after the column names")
      ->check(CLI::PositiveNumber);
  import_cmd->add_option("--min-sphericity-percent", min_sphericity,
                     "Refuse a retrieval with fewer spherical particles than this, % (default 95)")
      ->check(CLI::Range(0.0, 100.0));
  import_cmd->add_option("--layer", layer_out, "Aerosol-layer scale to write (default: NAME.layer.yaml beside the type)");

  return cli.Run(argc, argv, [&] {
    if (import_cmd->parsed()) {
      RunImportAeronet(cli, aeronet_file, import_out, layer_out, import_row, min_sphericity);
      return;
    }
    if (sphere->parsed()) {
      const std::complex<double> m = ParseIndex(m_text);
      std::vector<double> mu;
      for (double a : angles_deg) mu.push_back(a == 90.0 ? 0.0 : std::cos(a * std::numbers::pi / 180.0));
      const mie::MieSphereResult r = mie::MieSphere(x, m, mu);
      WriteText(sphere_out, mietool::SphereJson(r, angles_deg));
      return;
    }
    if (build->parsed()) {
      const std::vector<double> wavelengths = WavelengthGrid(wl_min, wl_max, wl_step);
      // Load and validate.
      mie::ParticleType type = mie::LoadParticleType(input);
      if (!mode_name.empty()) type = mie::SelectMode(type, mode_name);
      mie::CheckWavelengthCoverage(type, wavelengths.front(), wavelengths.back());
      // One core call.
      const auto t0 = std::chrono::steady_clock::now();
      mie::MieBuildOptions options;
      const mie::MieBuild result = mie::BuildMieTable(type, wavelengths, options, cli.Progress());
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      // Write.
      Provenance prov;
      prov.tool = cli.name();
      prov.parameters = mie::CanonicalParticleYaml(type, fs::path(input).parent_path()) +
                        fmt::format("wavelengths: {{min_nm: {}, max_nm: {}, step_nm: {}}}\n", FormatExact(wl_min),
                                    FormatExact(wl_max), FormatExact(wl_step)) +
                        (mode_name.empty() ? "" : "mode: " + mode_name + "\n") +
                        fmt::format("quadrature_tolerance: {}\nangles: {}\n",
                                    FormatExact(options.quadrature.tolerance), result.table.theta_rad.size());
      for (const fs::path& p : type.inputs) prov.AddInput(p);
      const bool changed = mie::WriteMieTable(output, result.table, prov);
      if (report_path.empty()) report_path = fs::path(output).replace_extension(".report.json").string();
      WriteFileIfChanged(report_path, mietool::BuildReportJson(type, result, options));
      if (!depfile.empty()) WriteDepfile(depfile, output, type.inputs);
      cli.Info(fmt::format("{} {} ({} wavelengths x {} angles, {:.2f} s)", changed ? "wrote" : "unchanged", output,
                           wavelengths.size(), result.table.theta_rad.size(), seconds));
      return;
    }
    if (dump->parsed()) {
      const mie::MieTable t = mie::ReadMieTable(table_path);
      const std::string source = "mie-tables dump of " + fs::path(table_path).filename().string() +
                                 " (particle type " + t.particle + ")";
      if (what == "spectral") {
        WriteText(dump_out, mietool::SpectralCsv(t, source));
        return;
      }
      if (dump_wl < 0.0) throw UsageError("--what phase needs --wavelength-nm");
      size_t wl = t.wavelengths();
      for (size_t i = 0; i < t.wavelengths(); ++i) {
        if (std::abs(t.wavelength_nm[i] - dump_wl) <= 1e-9 * dump_wl) wl = i;
      }
      if (wl == t.wavelengths()) {
        throw UsageError(fmt::format("--wavelength-nm {}: not a tabulated wavelength of {} ({}-{} nm, {} values)",
                                     FormatExact(dump_wl), table_path, FormatExact(t.wavelength_nm.front()),
                                     FormatExact(t.wavelength_nm.back()), t.wavelengths()));
      }
      WriteText(dump_out, mietool::PhaseCsv(t, wl, source));
    }
  });
}
