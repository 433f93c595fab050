// Where products live under the outputs folder (docs/pipeline.md, "Output layout"). Every path
// here is relative to the outputs folder; stages use these so that a later stage finds an
// earlier stage's products without knowing its internals.
#pragma once

#include <filesystem>
#include <string>

namespace skybake::paths {

// outputs/<atm>/components/profiles.yaml: the canonical profile component of an atmosphere.
inline std::filesystem::path ProfilesComponent(const std::string& atm) {
  return std::filesystem::path(atm) / "components" / "profiles.yaml";
}
// outputs/<atm>/profiles.exr: profile-import's table.
inline std::filesystem::path Profiles(const std::string& atm) {
  return std::filesystem::path(atm) / "profiles.exr";
}

}  // namespace skybake::paths
