#include "io/fileio.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
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

namespace {

// Writes `bytes` to `tmp` (create/truncate) and flushes it; on failure removes it and throws.
void WriteTemp(const std::filesystem::path& tmp, std::string_view bytes) {
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
}

void RenameOver(const std::filesystem::path& tmp, const std::filesystem::path& path) {
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    ThrowIo(path, "cannot replace file");
  }
}

void CreateParent(const std::filesystem::path& path) {
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(FileLoc{dir.string(), 0}, "cannot create folder: " + ec.message());
}

std::string TempSuffix(long pid) { return fmt::format(".tmp-{}", pid); }
constexpr std::string_view kJournalPrefix = ".skybake-commit-";

// The pid of a name ending in ".tmp-<digits>" (or a journal name), else 0.
long PidAfter(const std::string& name, std::string_view marker) {
  size_t at = name.rfind(marker);
  if (at == std::string::npos || at + marker.size() >= name.size()) return 0;
  long pid = 0;
  for (size_t i = at + marker.size(); i < name.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return 0;
    pid = pid * 10 + (name[i] - '0');
    if (pid > (1L << 30)) return 0;
  }
  return pid;
}

bool ProcessGone(long pid) {
  if (pid <= 0 || pid == static_cast<long>(::getpid())) return false;
  return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

// The open transaction: staged target -> its temporary file, in staging order.
struct Transaction {
  std::mutex mutex;
  bool open = false;
  std::vector<std::filesystem::path> order;
  std::map<std::filesystem::path, std::filesystem::path> staged;
  std::set<std::filesystem::path> recovered_dirs;
};

Transaction& Tx() {
  static Transaction tx;
  return tx;
}

std::filesystem::path Normal(const std::filesystem::path& p) {
  return std::filesystem::absolute(p).lexically_normal();
}

}  // namespace

void RecoverOutputFolder(const std::filesystem::path& dir_in) {
  const std::filesystem::path dir = dir_in.empty() ? std::filesystem::path(".") : dir_in;
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (dirent* e = ::readdir(d)) names.emplace_back(e->d_name);
    ::closedir(d);
  }
  // First complete the journals of dead runs: their staged files are the new set.
  for (const std::string& name : names) {
    if (name.rfind(kJournalPrefix, 0) != 0 || name.find(".tmp-") != std::string::npos) continue;
    const long pid = PidAfter(name, kJournalPrefix);
    if (!ProcessGone(pid)) continue;
    std::ifstream in(dir / name);
    std::string target;
    while (std::getline(in, target)) {
      if (target.empty()) continue;
      std::filesystem::path tmp = target + TempSuffix(pid);
      if (::access(tmp.c_str(), F_OK) == 0) ::rename(tmp.c_str(), target.c_str());
    }
    ::unlink((dir / name).c_str());
  }
  // Then remove what dead runs staged but never committed.
  for (const std::string& name : names) {
    const long pid = PidAfter(name, ".tmp-");
    if (pid != 0 && ProcessGone(pid)) ::unlink((dir / name).c_str());
  }
}

void BeginOutputTransaction() {
  Transaction& tx = Tx();
  std::lock_guard<std::mutex> lock(tx.mutex);
  tx.open = true;
  tx.order.clear();
  tx.staged.clear();
  tx.recovered_dirs.clear();
}

size_t CommitOutputTransaction() {
  Transaction& tx = Tx();
  std::lock_guard<std::mutex> lock(tx.mutex);
  size_t replaced = 0;
  if (!tx.order.empty()) {
    const long pid = static_cast<long>(::getpid());
    std::filesystem::path journal;
    if (tx.order.size() > 1) {
      // The journal lists every target, so a run killed between the renames is completed by
      // the next one (RecoverOutputFolder).
      std::string text;
      for (const auto& t : tx.order) text += t.string() + "\n";
      journal = tx.order.front().parent_path() / fmt::format("{}{}", kJournalPrefix, pid);
      std::filesystem::path journal_tmp = journal;
      journal_tmp += TempSuffix(pid);
      WriteTemp(journal_tmp, text);
      RenameOver(journal_tmp, journal);
    }
    int slow_ms = 0;
    if (const char* slow = std::getenv("SKYBAKE_TEST_SLOW_COMMIT_MS")) slow_ms = std::atoi(slow);
    for (const auto& target : tx.order) {
      RenameOver(tx.staged.at(target), target);
      ++replaced;
      if (slow_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(slow_ms));
    }
    if (!journal.empty()) ::unlink(journal.c_str());
  }
  tx.order.clear();
  tx.staged.clear();
  tx.recovered_dirs.clear();
  return replaced;
}

void AbortOutputTransaction() {
  Transaction& tx = Tx();
  std::lock_guard<std::mutex> lock(tx.mutex);
  for (const auto& [target, tmp] : tx.staged) ::unlink(tmp.c_str());
  tx.order.clear();
  tx.staged.clear();
  tx.recovered_dirs.clear();
  tx.open = false;
}

bool WriteFileIfChanged(const std::filesystem::path& path_in, std::string_view bytes) {
  Transaction& tx = Tx();
  std::unique_lock<std::mutex> lock(tx.mutex);
  if (!tx.open) {
    lock.unlock();
    if (SameContent(path_in, bytes)) return false;
    CreateParent(path_in);
    // Temporary file beside the target (same filesystem, so rename is atomic).
    std::filesystem::path tmp = path_in;
    tmp += TempSuffix(static_cast<long>(::getpid()));
    WriteTemp(tmp, bytes);
    RenameOver(tmp, path_in);
    return true;
  }
  const std::filesystem::path path = Normal(path_in);
  CreateParent(path);
  if (tx.recovered_dirs.insert(path.parent_path()).second) RecoverOutputFolder(path.parent_path());
  auto it = tx.staged.find(path);
  if (SameContent(path, bytes)) {
    if (it != tx.staged.end()) {  // staged earlier in this command, now back to what is on disk
      ::unlink(it->second.c_str());
      tx.staged.erase(it);
      tx.order.erase(std::find(tx.order.begin(), tx.order.end(), path));
    }
    return false;
  }
  std::filesystem::path tmp = path;
  tmp += TempSuffix(static_cast<long>(::getpid()));
  WriteTemp(tmp, bytes);
  if (it == tx.staged.end()) {
    tx.staged.emplace(path, tmp);
    tx.order.push_back(path);
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
