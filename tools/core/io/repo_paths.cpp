#include "io/repo_paths.h"

#include <system_error>

#include <fmt/format.h>

#include "io/error.h"

namespace fs = std::filesystem;

namespace skybake {

std::optional<fs::path> ExecutableDir() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec || exe.empty()) return std::nullopt;
  return exe.parent_path();
}

std::optional<fs::path> FindUpwards(const fs::path& start, const fs::path& relative) {
  std::error_code ec;
  fs::path dir = fs::absolute(start, ec);
  if (ec) return std::nullopt;
  dir = dir.lexically_normal();
  while (true) {
    fs::path candidate = dir / relative;
    if (fs::is_regular_file(candidate, ec)) return candidate;
    if (!dir.has_parent_path() || dir.parent_path() == dir) return std::nullopt;
    dir = dir.parent_path();
  }
}

std::optional<fs::path> RepoRoot() {
  const fs::path marker = fs::path("ocio") / "config.ocio";
  std::optional<fs::path> found;
  if (std::optional<fs::path> exe_dir = ExecutableDir()) found = FindUpwards(*exe_dir, marker);
  std::error_code ec;
  if (!found) {
    const fs::path cwd = fs::current_path(ec);
    if (!ec) found = FindUpwards(cwd, marker);
  }
  if (!found) return std::nullopt;
  fs::path root = fs::weakly_canonical(found->parent_path().parent_path(), ec);
  if (ec) return std::nullopt;
  return root;
}

fs::path FindRepoFile(const fs::path& relative) {
  std::string searched;
  if (std::optional<fs::path> exe_dir = ExecutableDir()) {
    if (std::optional<fs::path> found = FindUpwards(*exe_dir, relative)) return *found;
    searched = exe_dir->string();
  }
  std::error_code ec;
  fs::path cwd = fs::current_path(ec);
  if (!ec) {
    if (std::optional<fs::path> found = FindUpwards(cwd, relative)) return *found;
    if (!searched.empty()) searched += " and ";
    searched += cwd.string();
  }
  throw InputError(FileLoc{relative.string(), 0},
                   fmt::format("not found in the skybake repository: searched upwards from {}", searched));
}

}  // namespace skybake
