// The pipeline's stages, in order. Adding a tool: write stage_<tool>.cpp and add one line here.
#include "stage.h"

namespace skybake {

std::unique_ptr<Stage> MakeProfileImportStage();
std::unique_ptr<Stage> MakeMieTablesStage();
std::unique_ptr<Stage> MakeSkyRenderStage();
std::unique_ptr<Stage> MakeNoiseGenStage();
std::unique_ptr<Stage> MakeCumulusMapStage();
std::unique_ptr<Stage> MakeLutPackStage();
std::unique_ptr<Stage> MakeFogFitStage();

std::vector<std::unique_ptr<Stage>> MakeStages() {
  std::vector<std::unique_ptr<Stage>> s;
  s.push_back(MakeProfileImportStage());
  s.push_back(MakeMieTablesStage());
  s.push_back(MakeSkyRenderStage());
  s.push_back(MakeLutPackStage());  // after sky-render: uses its render components
  s.push_back(MakeFogFitStage());   // after sky-render: uses its render components
  s.push_back(MakeNoiseGenStage());
  s.push_back(MakeCumulusMapStage());  // after noise-gen: it owns the `clouds` section's unknown keys
  return s;
}

}  // namespace skybake
