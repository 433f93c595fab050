// The pipeline's stages, in order. Adding a tool: write stage_<tool>.cpp and add one line here.
#include "stage.h"

namespace skybake {

std::unique_ptr<Stage> MakeProfileImportStage();

std::vector<std::unique_ptr<Stage>> MakeStages() {
  std::vector<std::unique_ptr<Stage>> s;
  s.push_back(MakeProfileImportStage());
  return s;
}

}  // namespace skybake
