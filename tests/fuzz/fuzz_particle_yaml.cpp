// The particle type loader (optics/particle_type.h) on arbitrary bytes: modes, refractive
// indices (tables of the repository, read through the seeds' relative paths), weights.
#include "fuzz_common.h"
#include "optics/particle_type.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Guarded([&] {
    YamlDocument doc = YamlDocument::Parse(fuzz::Text(data, size), "fuzz.yaml", fuzz::SourceDir("particles"));
    mie::ParticleType type = mie::ParseParticleType(doc, "fuzz");
    (void)mie::CanonicalParticleYaml(type, fuzz::SourceDir("particles"));
  });
  return 0;
}
