// Progress reporting from the library without printing (docs/developing.md "Rules", 5): long
// computations take a ProgressFn and call it with a short stage name and the fraction done in
// [0, 1]. The tool decides how to show it (io/cli.h logs rate-limited lines on stderr). Calls may come from any
// thread; the callback must be thread-safe (ToolCli's is).
#pragma once

#include <functional>
#include <string_view>

namespace skybake {

using ProgressFn = std::function<void(std::string_view stage, double fraction)>;

inline void ReportProgress(const ProgressFn& fn, std::string_view stage, double fraction) {
  if (fn) fn(stage, fraction);
}

}  // namespace skybake
