#include "io/error.h"

#include <algorithm>

namespace skybake {

std::string FileLoc::ToString() const {
  if (line > 0) return file + ":" + std::to_string(line);
  return file;
}

std::string Diagnostic::ToString() const {
  if (loc.file.empty()) return message;
  return loc.ToString() + ": " + message;
}

namespace {
std::string JoinDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  std::string out;
  for (const Diagnostic& d : diagnostics) {
    if (!out.empty()) out += "\n";
    out += d.ToString();
  }
  return out;
}
}  // namespace

InputError::InputError(FileLoc loc, const std::string& message)
    : InputError(std::vector<Diagnostic>{{std::move(loc), message}}) {}

InputError::InputError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(JoinDiagnostics(diagnostics)), diagnostics_(std::move(diagnostics)) {}

void Diagnostics::Add(FileLoc loc, std::string message) {
  items_.push_back({std::move(loc), std::move(message)});
}

void Diagnostics::ThrowIfAny() const {
  if (items_.empty()) return;
  std::vector<Diagnostic> sorted = items_;
  std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic& a, const Diagnostic& b) {
    if (a.loc.file != b.loc.file) return a.loc.file < b.loc.file;
    return a.loc.line < b.loc.line;
  });
  throw InputError(std::move(sorted));
}

namespace detail {
void CheckFailed(const char* file, int line, const std::string& what) {
  throw InternalError(std::string("internal check failed at ") + file + ":" + std::to_string(line) +
                      ": " + what);
}
}  // namespace detail

}  // namespace skybake
