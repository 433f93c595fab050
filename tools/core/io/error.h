// Typed errors for the whole core library.
//
// The library never prints and never exits: it throws one of these, and each tool's main
// catches once (io/cli.h) and turns it into `tool: file:line: message` and an exit code
// (docs/developing.md "Rules", 6):
//   InputError    - the user's input is wrong (bad YAML/CSV/EXR, out-of-range value, missing
//                   file). Exit code 1. Carries one or more located diagnostics, so a loader can
//                   report every problem of a file at once.
//   UsageError    - the command line is wrong. Exit code 2.
//   InternalError - an invariant of the code broke (SKYBAKE_CHECK). Exit code 3.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace skybake {

// Where a problem is: a file and, for text files, a 1-based line (0 = whole file).
struct FileLoc {
  std::string file;
  int line = 0;

  // "file:line" or "file" when the line is unknown.
  std::string ToString() const;
};

struct Diagnostic {
  FileLoc loc;
  std::string message;

  // "file:line: message"; "message" alone when there is no file.
  std::string ToString() const;
};

class InputError : public std::runtime_error {
 public:
  InputError(FileLoc loc, const std::string& message);
  explicit InputError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InternalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Collects every problem found while loading, then throws them together.
class Diagnostics {
 public:
  void Add(FileLoc loc, std::string message);
  bool empty() const { return items_.empty(); }
  size_t size() const { return items_.size(); }
  const std::vector<Diagnostic>& items() const { return items_; }
  // Throws InputError with every collected diagnostic, sorted by file then line (stable), if any.
  void ThrowIfAny() const;

 private:
  std::vector<Diagnostic> items_;
};

namespace detail {
[[noreturn]] void CheckFailed(const char* file, int line, const std::string& what);
template <typename A, typename B>
std::string FormatOperands(const char* expr_a, const A& a, const char* op, const char* expr_b,
                           const B& b) {
  std::ostringstream s;
  s.precision(17);
  s << expr_a << " " << op << " " << expr_b << " (" << a << " vs " << b << ")";
  return s.str();
}
}  // namespace detail

}  // namespace skybake

// CHECK macros for internal invariants: active in every build type, they print the operands
// (pbrt-v4 util/check.h style) and throw InternalError.
#define SKYBAKE_CHECK(cond) \
  do { \
    if (!(cond)) ::skybake::detail::CheckFailed(__FILE__, __LINE__, #cond); \
  } while (0)
#define SKYBAKE_CHECK_OP(a, op, b) \
  do { \
    const auto& skybake_a_ = (a); \
    const auto& skybake_b_ = (b); \
    if (!(skybake_a_ op skybake_b_)) \
      ::skybake::detail::CheckFailed( \
          __FILE__, __LINE__, ::skybake::detail::FormatOperands(#a, skybake_a_, #op, #b, skybake_b_)); \
  } while (0)
#define SKYBAKE_CHECK_EQ(a, b) SKYBAKE_CHECK_OP(a, ==, b)
#define SKYBAKE_CHECK_LT(a, b) SKYBAKE_CHECK_OP(a, <, b)
#define SKYBAKE_CHECK_LE(a, b) SKYBAKE_CHECK_OP(a, <=, b)
#define SKYBAKE_CHECK_GT(a, b) SKYBAKE_CHECK_OP(a, >, b)
#define SKYBAKE_CHECK_GE(a, b) SKYBAKE_CHECK_OP(a, >=, b)
