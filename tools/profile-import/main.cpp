// profile-import: the vertical profiles of one atmosphere (air, ozone, aerosol layer shapes)
// on its altitude grid, as an EXR table (atmosphere/vertical_profiles.h has the channels).
//
//   profile-import ATMOSPHERE.yaml -o profiles.exr [--depfile profiles.exr.d]
//                  [--altitude-step-m 100]
#include <filesystem>

#include "atmosphere/spec.h"
#include "atmosphere/vertical_profiles.h"
#include "io/cli.h"
#include "io/exr.h"
#include "io/fileio.h"

namespace fs = std::filesystem;
using namespace skybake;

int main(int argc, char** argv) {
  ToolCli cli("profile-import",
              "Writes the vertical profiles of an atmosphere (US Std 1976 air, ozone, aerosol layer shapes)\n"
              "on its altitude grid as an OpenEXR table. See docs/atmosphere.md.");
  std::string input, output, depfile;
  double step_m = 0.0;
  cli.app().add_option("atmosphere", input, "Atmosphere YAML (a full atmosphere or its profiles component)")
      ->required();
  cli.app().add_option("-o,--output", output, "Output EXR table")->required();
  cli.app().add_option("--depfile", depfile, "Write a Make-style depfile listing every file read");
  cli.app()
      .add_option("--altitude-step-m", step_m,
                  "Altitude grid step in m when the atmosphere has no 'grid' section (default 100)")
      ->check(CLI::Range(1.0, 10000.0));
  return cli.Run(argc, argv, [&] {
    // Load and validate.
    AtmosphereSpec spec = LoadAtmosphere(input);
    if (!spec.grid) spec.grid = GridSpec{step_m > 0.0 ? step_m : 100.0};
    // One core call.
    VerticalProfiles profiles = ComputeProfiles(spec);
    // Write.
    ExrImage image = TableToImage(ProfilesToTable(profiles));
    Provenance prov;
    prov.tool = cli.name();
    prov.parameters = CanonicalProfilesYaml(spec, fs::path(input).parent_path());
    prov.AddInput(input);
    for (const fs::path& p : profiles.inputs_read) prov.AddInput(p);
    SetProvenance(image, prov);
    if (profiles.has_ozone) image.doubles["skybake.ozone.column_du"] = profiles.ozone_column_du;
    image.doubles["skybake.planet.radius_m"] = spec.planet->radius_m;
    image.doubles["skybake.planet.top_m"] = spec.planet->top_m;
    bool changed = WriteExr(output, image);
    if (!depfile.empty()) {
      std::vector<fs::path> deps{input};
      deps.insert(deps.end(), profiles.inputs_read.begin(), profiles.inputs_read.end());
      WriteDepfile(depfile, output, deps);
    }
    cli.Info(std::string(changed ? "wrote " : "unchanged ") + output);
  });
}
