#include "io/fileio.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "io/error.h"

namespace skybake {

std::string ReadFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(FileLoc{path.string(), 0}, "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

bool SameContent(const std::filesystem::path& path, std::string_view bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  auto size = std::filesystem::file_size(path, ec);
  if (ec || size != bytes.size()) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::string existing(bytes.size(), '\0');
  in.read(existing.data(), static_cast<std::streamsize>(existing.size()));
  return in.gcount() == static_cast<std::streamsize>(bytes.size()) && existing == bytes;
}

[[noreturn]] void ThrowIo(const std::filesystem::path& path, const std::string& what) {
  throw InputError(FileLoc{path.string(), 0}, what + ": " + std::strerror(errno));
}

}  // namespace

bool WriteFileIfChanged(const std::filesystem::path& path, std::string_view bytes) {
  if (SameContent(path, bytes)) return false;
  std::filesystem::path dir = path.parent_path();
  if (!dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw InputError(FileLoc{dir.string(), 0}, "cannot create folder: " + ec.message());
  }
  // Temporary file beside the target (same filesystem, so rename is atomic).
  std::filesystem::path tmp = path;
  tmp += fmt::format(".tmp-{}", static_cast<long>(::getpid()));
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) ThrowIo(tmp, "cannot create temporary file");

  size_t chunk = bytes.size();
  int slow_ms = 0;
  if (const char* slow = std::getenv("SKYBAKE_TEST_SLOW_WRITE_MS")) {
    slow_ms = std::atoi(slow);
    if (slow_ms > 0) chunk = 4096;
  }
  size_t done = 0;
  while (done < bytes.size()) {
    size_t n = std::min(chunk, bytes.size() - done);
    ssize_t w = ::write(fd, bytes.data() + done, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      int saved = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      errno = saved;
      ThrowIo(tmp, "write failed");
    }
    done += static_cast<size_t>(w);
    if (slow_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(slow_ms));
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    ThrowIo(tmp, "cannot flush temporary file");
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    ThrowIo(path, "cannot replace file");
  }
  return true;
}

namespace {
std::string EscapeDepPath(const std::string& p) {
  std::string out;
  for (char c : p) {
    if (c == ' ' || c == '#') out += '\\';
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}
}  // namespace

void WriteDepfile(const std::filesystem::path& depfile, const std::filesystem::path& target,
                  const std::vector<std::filesystem::path>& inputs) {
  std::string s = EscapeDepPath(target.string()) + ":";
  for (const auto& in : inputs) s += " \\\n  " + EscapeDepPath(in.string());
  s += "\n";
  WriteFileIfChanged(depfile, s);
}

std::string HashBytes(std::string_view bytes) {
  return fmt::format("{:016x}", static_cast<unsigned long long>(XXH3_64bits(bytes.data(), bytes.size())));
}

std::string HashFile(const std::filesystem::path& path) { return HashBytes(ReadFileBytes(path)); }

}  // namespace skybake
