// The cloud recipe loaders (noise/volume.h, noise/cumulus.h, noise/coverage.h) on arbitrary
// bytes: each input goes through all three.
#include "fuzz_common.h"
#include "noise/coverage.h"
#include "noise/cumulus.h"
#include "noise/volume.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = fuzz::Text(data, size);
  const std::filesystem::path dir = fuzz::SourceDir("clouds");
  fuzz::Guarded([&] { noise::ParseVolumeSpec(YamlDocument::Parse(text, "fuzz.yaml", dir), "fuzz"); });
  fuzz::Guarded([&] { noise::ParseCumulusSpec(YamlDocument::Parse(text, "fuzz.yaml", dir)); });
  fuzz::Guarded([&] { noise::ParseCoverageSpec(YamlDocument::Parse(text, "fuzz.yaml", dir)); });
  return 0;
}
