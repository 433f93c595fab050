// Finding files that belong to the skybake repository itself (the OCIO config, the standard
// colorimetric tables), for tools run interactively without an explicit path.
//
// The repository is found by walking up from a start folder until `<folder>/<relative>` exists.
// FindRepoFile tries, in order:
//   1. the folder of the running executable (/proc/self/exe) and its parents: a tool built in
//      any build folder inside the repository (build/dev/bin, build/color/bin, ...) finds it;
//   2. the current working folder and its parents.
// Pipelines should not rely on this: the generator passes explicit paths (and lists them in
// depfiles); this is the fallback for a person typing a command.
#pragma once

#include <filesystem>
#include <optional>

namespace skybake {

// Folder of the running executable, or nullopt where /proc/self/exe cannot be read.
std::optional<std::filesystem::path> ExecutableDir();

// First `<d>/<relative>` that exists, for d = start, its parent, ..., the root; nullopt if none.
std::optional<std::filesystem::path> FindUpwards(const std::filesystem::path& start,
                                                 const std::filesystem::path& relative);

// `relative` (e.g. "ocio/config.ocio") inside the repository, searched as described above.
// Throws InputError naming `relative` and the folders searched when it is not found.
std::filesystem::path FindRepoFile(const std::filesystem::path& relative);

// The repository's folder (symbolic links resolved): where FindRepoFile finds ocio/config.ocio;
// nullopt when there is none (a tool installed outside any checkout).
std::optional<std::filesystem::path> RepoRoot();

}  // namespace skybake
