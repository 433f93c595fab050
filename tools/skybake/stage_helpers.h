// What several stages read or emit the same way: an atmosphere of the pipeline by name, the Mie
// tables an atmosphere's render depends on, and the GT7 time-mapping name of a `time_mapping` key
// (luts and fog sections).
#pragma once

#include <string>
#include <vector>

#include "atmosphere/spec.h"
#include "io/error.h"
#include "io/yaml.h"
#include "pipeline.h"

namespace skybake {

// The pipeline's atmosphere called `name`; nullptr, with "<key>: '<name>' is not an atmosphere of
// this pipeline (<every name>)" added at `loc`, if there is none. `key` names the list that
// referred to it, e.g. "luts.skies".
const PipelineAtmosphere* FindAtmosphere(const Pipeline& pipeline, const std::string& name, const std::string& key,
                                         const FileLoc& loc, Diagnostics* diags);

// The Mie tables (outputs/mie/<type>.exr, paths::MieTable) of the particle types of an
// atmosphere's aerosol layers, each once, in name order: implicit inputs of every edge that
// renders the atmosphere (sky-render reads them through --mie-dir).
std::vector<std::string> MieTableInputs(const AtmosphereSpec& spec);

// True iff `name` is a time mapping lut/gt7_mapping.h's TimeMapping::ParseName accepts: gt7 or
// gt7-quadratic, optionally ":<upper>+<lower>" slices with upper, lower >= 2 and upper + lower
// <= 4096, written without leading zeros or signs (the generator does not link the lut module).
bool Gt7TimeMappingNameOk(const std::string& name);

// The section's `time_mapping` key if present and a GT7 mapping name, else `fallback` (an error
// at the key for a name Gt7TimeMappingNameOk rejects).
std::string TimeMappingOr(YamlMap& section, const std::string& fallback);

}  // namespace skybake
