// pipeline.yaml: what the default bake produces (docs/pipeline.md).
//
//   outputs: outputs                  # build folder, relative to pipeline.yaml
//   altitude_step_m: 100              # default profile grid (an atmosphere's grid wins)
//   wavelengths: {min_nm: 360, max_nm: 830, step_nm: 5}   # the spectral grid of every tool
//   atmospheres: [atmospheres/clear.yaml, ...]
//   pools: {render: 1}                # Ninja pools for heavy tools (name: depth)
//   launchers: {sky-render: "srun --quiet -n1"}           # optional per-tool command prefix
//   ... plus one section per stage that has settings (mie, sky, clouds, ...)
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "atmosphere/spec.h"

namespace skybake {

struct PipelineAtmosphere {
  std::string name;
  std::filesystem::path file;  // absolute
  AtmosphereSpec spec;         // grid resolved (pipeline default if the atmosphere has none)
};

struct PipelineWavelengths {
  double min_nm = 360.0;
  double max_nm = 830.0;
  double step_nm = 5.0;
  std::vector<double> Values() const;
};

struct Pipeline {
  std::filesystem::path file;      // absolute path of pipeline.yaml
  std::filesystem::path root_dir;  // its folder
  std::filesystem::path out_dir;   // absolute outputs folder
  double altitude_step_m = 100.0;
  PipelineWavelengths wavelengths;
  std::vector<PipelineAtmosphere> atmospheres;
  std::map<std::string, int> pools;
  std::map<std::string, std::string> launchers;
  std::vector<std::filesystem::path> files_read;  // every file read while loading (absolute)
};

class Stage;

// Loads pipeline.yaml and every atmosphere it lists; stages read their own sections.
// Throws InputError with every problem (file:line) of pipeline.yaml and the atmospheres.
Pipeline LoadPipeline(const std::filesystem::path& path, const std::vector<Stage*>& stages);

}  // namespace skybake
