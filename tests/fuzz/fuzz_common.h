// Shared by the libFuzzer targets (tests/fuzz, docs/developing.md "Sanitizers and fuzzing"): a loader may
// reject any input with InputError or UsageError (exit 1 or 2 in a tool); anything else that
// escapes - InternalError (a tool's exit 3), another exception, a sanitizer report, a signal -
// is a crash of the target. SKYBAKE_SOURCE_DIR resolves the relative paths of the seeds (the
// repository's own files), so that loaders get past their file checks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "io/error.h"

namespace skybake::fuzz {

inline std::string Text(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

inline std::filesystem::path SourceDir(const char* sub) {
  return std::filesystem::path(SKYBAKE_SOURCE_DIR) / sub;
}

// Runs `f`; bad input is an expected outcome.
template <typename F>
void Guarded(F&& f) {
  try {
    f();
  } catch (const InputError&) {
  } catch (const UsageError&) {
  }
}

}  // namespace skybake::fuzz
