// ocio-config-gen: writes skybake's OpenColorIO config (ocio/config.ocio) from code, so that the
// checked-in config is reproducible (color/ocio_config.h describes its content; docs/color.md §6).
//
//   ocio-config-gen --data-dir atmospheres/data -o ocio/config.ocio [--depfile config.ocio.d]
//
// Reads the CIE 2006 2° colour-matching functions and the CIE D65 spectrum (for the "CIE 2006
// 2deg XYZ" space), builds and validates the config with the OCIO API, and writes it only when
// its bytes change.
#include <filesystem>

#include "color/ocio_config.h"
#include "io/cli.h"
#include "io/fileio.h"
#include "spectrum/cmf.h"
#include "spectrum/spectrum.h"

namespace fs = std::filesystem;
using namespace skybake;

int main(int argc, char** argv) {
  ToolCli cli("ocio-config-gen",
              "Writes skybake's OpenColorIO config (reference CIE-XYZ-D65; Linear Rec.2020, Linear Rec.709,\n"
              "CIE 2006 2deg XYZ, ACES2065-1; sRGB, Rec.1886 and Rec.2100-PQ displays). See docs/color.md.");
  std::string data_dir, output, depfile;
  cli.app().add_option("--data-dir", data_dir, "Folder with cie2006_2deg_xyz_cmf_1nm.csv and cie_d65_1nm.csv")->required();
  cli.app().add_option("-o,--output", output, "Output config (ocio/config.ocio)")->required();
  cli.app().add_option("--depfile", depfile, "Write a Make-style depfile listing every file read");
  return cli.Run(argc, argv, [&] {
    // Load.
    const fs::path cmf_path = fs::path(data_dir) / CmfFileName(Observer::kCie2006_2deg);
    const fs::path d65_path = fs::path(data_dir) / "cie_d65_1nm.csv";
    const Cmf cmf = Cmf::Load(cmf_path, Observer::kCie2006_2deg);
    const TabulatedSpectrum d65 = LoadSpectrumColumn(d65_path, "relative_spd");
    // One core call. The provenance names the inputs by file name and content hash only, so the
    // bytes do not depend on where the repository is.
    const std::string provenance =
        "Inputs: " + cmf_path.filename().string() + " (xxh3 " + HashFile(cmf_path) + "), " +
        d65_path.filename().string() + " (xxh3 " + HashFile(d65_path) + ").";
    const OcioConfigBuild build = BuildOcioConfig(cmf, d65, provenance);
    // Write.
    const bool changed = WriteFileIfChanged(output, build.text);
    if (!depfile.empty()) WriteDepfile(depfile, output, {cmf_path, d65_path});
    cli.Info(std::string(changed ? "wrote " : "unchanged ") + output);
  });
}
