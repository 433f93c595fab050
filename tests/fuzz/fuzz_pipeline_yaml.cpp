// The pipeline loader of the generator (tools/skybake/pipeline.h, with every stage's section)
// on arbitrary bytes, written to a file in the repository's root folder so that the seeds'
// relative paths (atmospheres/..., clouds/...) resolve.
#include <unistd.h>

#include <fstream>

#include "fuzz_common.h"
#include "pipeline.h"
#include "stage.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<std::unique_ptr<Stage>> owned = MakeStages();
  static std::vector<Stage*> stages;
  static const std::filesystem::path file = [] {
    for (const auto& s : owned) stages.push_back(s.get());
    return std::filesystem::temp_directory_path() / ("skybake_fuzz_pipeline_" + std::to_string(::getpid()) + ".yaml");
  }();
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(SKYBAKE_SOURCE_DIR);
  fuzz::Guarded([&] { LoadPipeline(file, stages); });
  std::filesystem::current_path(cwd);
  return 0;
}
