// The atmosphere file loader (atmosphere/spec.h) on arbitrary bytes, with the emitters of its
// canonical components, which must read back as a valid atmosphere.
#include "atmosphere/spec.h"
#include "fuzz_common.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Guarded([&] {
    const std::filesystem::path dir = fuzz::SourceDir("atmospheres");
    YamlDocument doc = YamlDocument::Parse(fuzz::Text(data, size), "fuzz.yaml", dir);
    AtmosphereSpec spec = ParseAtmosphere(doc, "fuzz");
    const std::string profiles = CanonicalProfilesYaml(spec, dir);
    const std::string render = CanonicalRenderYaml(spec, dir);
    // A canonical component of a valid atmosphere is itself valid: this must not throw.
    try {
      ParseAtmosphere(YamlDocument::Parse(profiles, "profiles.yaml", dir), "fuzz");
      ParseAtmosphere(YamlDocument::Parse(render, "render.yaml", dir), "fuzz");
    } catch (const InputError& e) {
      throw InternalError(std::string("a canonical component does not read back: ") + e.what());
    }
  });
  return 0;
}
