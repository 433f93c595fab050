#include "stage_helpers.h"

#include <fmt/format.h>

#include <cstdio>
#include <set>

#include "paths.h"

namespace skybake {

const PipelineAtmosphere* FindAtmosphere(const Pipeline& pipeline, const std::string& name, const std::string& key,
                                         const FileLoc& loc, Diagnostics* diags) {
  const PipelineAtmosphere* found = nullptr;
  for (const PipelineAtmosphere& p : pipeline.atmospheres) {
    if (p.name == name) found = &p;
  }
  if (!found) {
    std::string names;
    for (const PipelineAtmosphere& p : pipeline.atmospheres) names += (names.empty() ? "" : ", ") + p.name;
    diags->Add(loc, key + ": '" + name + "' is not an atmosphere of this pipeline (" + names + ")");
  }
  return found;
}

std::vector<std::string> MieTableInputs(const AtmosphereSpec& spec) {
  std::set<std::string> particles;
  for (const AerosolLayerSpec& layer : spec.aerosols) {
    if (layer.particle) particles.insert(layer.particle->stem().string());
  }
  std::vector<std::string> inputs;
  for (const std::string& p : particles) inputs.push_back(paths::MieTable(p).generic_string());
  return inputs;
}

bool Gt7TimeMappingNameOk(const std::string& name) {
  const std::string base = name.substr(0, name.find(':'));
  if (base != "gt7" && base != "gt7-quadratic") return false;
  if (name.find(':') == std::string::npos) return true;
  int u = 0, l = 0;
  char tail = 0;
  const std::string counts = name.substr(name.find(':') + 1);
  return std::sscanf(counts.c_str(), "%d+%d%c", &u, &l, &tail) == 2 && u >= 2 && l >= 2 && u + l <= 4096 &&
         counts == fmt::format("{}+{}", u, l);
}

std::string TimeMappingOr(YamlMap& section, const std::string& fallback) {
  std::optional<YamlNode> tm = section.Get("time_mapping");
  if (!tm) return fallback;
  const std::optional<std::string> s = tm->ToString();
  if (!s) return fallback;
  if (!Gt7TimeMappingNameOk(*s)) {
    tm->ErrorExpected("gt7 or gt7-quadratic, optionally with :<upper>+<lower> slices (e.g. gt7:3+2)");
    return fallback;
  }
  return *s;
}

}  // namespace skybake
