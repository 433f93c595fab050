#include "io/fileio.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
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
  CompleteCommittedJournals(path.parent_path());
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

namespace {

std::vector<std::string> Listing(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (dirent* e = ::readdir(d)) names.emplace_back(e->d_name);
    ::closedir(d);
  }
  return names;
}

void SyncFolder(const std::filesystem::path& dir) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void LockExclusive(int fd) {
  while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
  }
}

// Whether the file behind `fd` still has a name (a journal its writer or another reader has
// completed and removed has none).
bool StillLinked(int fd) {
  struct stat st {};
  return ::fstat(fd, &st) == 0 && st.st_nlink > 0;
}

std::vector<std::filesystem::path> JournalTargets(int fd) {
  std::string text;
  char buf[4096];
  ssize_t n = 0;
  ::lseek(fd, 0, SEEK_SET);
  while ((n = ::read(fd, buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR)) {
    if (n > 0) text.append(buf, static_cast<size_t>(n));
  }
  std::vector<std::filesystem::path> targets;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) targets.emplace_back(line);
  }
  return targets;
}

// The folders of `targets`, each once, in order.
std::vector<std::filesystem::path> FoldersOf(const std::vector<std::filesystem::path>& targets) {
  std::vector<std::filesystem::path> dirs;
  for (const auto& t : targets) {
    if (std::find(dirs.begin(), dirs.end(), t.parent_path()) == dirs.end()) dirs.push_back(t.parent_path());
  }
  return dirs;
}

std::string JournalName(long pid) { return fmt::format("{}{}", kJournalPrefix, pid); }

// Rolls a committed transaction of process `pid` forward: renames every staged file its
// journal lists over its target, flushes the folders, then removes the journal's copies (and
// any pending copy) in every folder. `fd` is the locked journal.
void RollForward(const std::filesystem::path& journal, int fd, long pid) {
  const std::vector<std::filesystem::path> targets = JournalTargets(fd);
  const std::vector<std::filesystem::path> dirs = FoldersOf(targets);
  std::string failed;
  for (const auto& target : targets) {
    std::filesystem::path tmp = target;
    tmp += TempSuffix(pid);
    if (::rename(tmp.c_str(), target.c_str()) != 0 && errno != ENOENT && failed.empty()) {
      failed = target.string() + ": " + std::strerror(errno);
    }
  }
  for (const auto& dir : dirs) SyncFolder(dir);
  if (!failed.empty()) {
    throw InputError(FileLoc{journal.string(), 0}, "cannot complete an interrupted commit: cannot replace " + failed);
  }
  const std::string name = JournalName(pid);
  for (const auto& dir : dirs) {
    ::unlink((dir / name).c_str());
    ::unlink((dir / (name + TempSuffix(pid))).c_str());
  }
  ::unlink(journal.c_str());
}

// Completes the committed transactions whose journal lies in `dir` (see the file comment of
// fileio.h). A journal is locked (flock) by its writer from before it has its name until it is
// removed, so taking the lock waits for a live commit to end; a journal still named once the
// lock is ours is a dead run's, and is rolled forward. A pending copy (the journal's
// temporary file, written in every folder before any copy gets its name) of a dead run means
// that run died before or while naming its copies: its transaction is committed when a copy in
// any of its folders has its name; otherwise, with `remove_uncommitted`, the pending copy goes
// (and with it the protection of that run's staged files in this folder).
void CompleteJournals(const std::filesystem::path& dir, bool remove_uncommitted) {
  const long self = static_cast<long>(::getpid());
  for (const std::string& name : Listing(dir)) {
    if (name.rfind(kJournalPrefix, 0) != 0) continue;
    const bool pending = name.find(".tmp-") != std::string::npos;
    const long pid = PidAfter(pending ? name.substr(0, name.find(".tmp-")) : name, kJournalPrefix);
    if (pid <= 0 || (pending && !ProcessGone(pid))) continue;
    const std::filesystem::path journal = dir / name;
    const int fd = ::open(journal.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;  // completed meanwhile
    if (pid == self) {
      // This process's own commit holds the lock while it runs (and does no reads); a journal
      // of this pid that is free is a dead run's whose pid came back.
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd);
        continue;
      }
    } else {
      LockExclusive(fd);
    }
    try {
      if (StillLinked(fd)) {
        if (!pending) {
          RollForward(journal, fd, pid);
        } else {
          bool committed = false;
          for (const auto& d : FoldersOf(JournalTargets(fd))) {
            const std::filesystem::path named = d / JournalName(pid);
            const int nfd = ::open(named.c_str(), O_RDONLY | O_CLOEXEC);
            if (nfd < 0) continue;
            LockExclusive(nfd);
            if (StillLinked(nfd)) {
              committed = true;
              try {
                RollForward(named, nfd, pid);
              } catch (...) {
                ::close(nfd);
                throw;
              }
            }
            ::close(nfd);
            if (committed) break;
          }
          if (!committed && remove_uncommitted) ::unlink(journal.c_str());
        }
      }
    } catch (...) {
      ::close(fd);
      throw;
    }
    ::close(fd);
  }
}

}  // namespace

void CompleteCommittedJournals(const std::filesystem::path& dir) {
  CompleteJournals(dir.empty() ? std::filesystem::path(".") : dir, false);
}

void RecoverOutputFolder(const std::filesystem::path& dir_in) {
  const std::filesystem::path dir = dir_in.empty() ? std::filesystem::path(".") : dir_in;
  CompleteJournals(dir, true);
  // Then remove what dead runs staged but never committed: their temporary files, where no
  // journal (named or pending) of theirs is left in this folder.
  const std::vector<std::string> names = Listing(dir);
  std::set<long> journaled;
  for (const std::string& name : names) {
    if (name.rfind(kJournalPrefix, 0) != 0) continue;
    const std::string base = name.find(".tmp-") != std::string::npos ? name.substr(0, name.find(".tmp-")) : name;
    journaled.insert(PidAfter(base, kJournalPrefix));
  }
  for (const std::string& name : names) {
    if (name.rfind(kJournalPrefix, 0) == 0) continue;
    const long pid = PidAfter(name, ".tmp-");
    if (pid != 0 && !journaled.count(pid) && ProcessGone(pid)) ::unlink((dir / name).c_str());
  }
}

void RecoverOutputTree(const std::filesystem::path& root) {
  std::error_code ec;
  if (!std::filesystem::is_directory(root, ec)) return;
  std::vector<std::filesystem::path> dirs = {root};
  for (auto it = std::filesystem::recursive_directory_iterator(root, ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_directory(ec) && !it->is_symlink(ec)) dirs.push_back(it->path());
  }
  // Every journal first (a transaction may span folders), then the stale temporary files.
  for (const auto& d : dirs) CompleteJournals(d, false);
  for (const auto& d : dirs) RecoverOutputFolder(d);
}

void BeginOutputTransaction() {
  Transaction& tx = Tx();
  std::lock_guard<std::mutex> lock(tx.mutex);
  tx.open = true;
  tx.order.clear();
  tx.staged.clear();
  tx.recovered_dirs.clear();
}

namespace {

// Creates the pending copy `<dir>/.skybake-commit-<pid>.tmp-<pid>` of the journal, locked,
// written and flushed; returns its descriptor (the lock lasts until it is closed).
int WritePendingJournal(const std::filesystem::path& pending, const std::string& text) {
  const int fd = ::open(pending.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) ThrowIo(pending, "cannot create the commit journal");
  LockExclusive(fd);
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t w = ::write(fd, text.data() + done, text.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) {
      const int saved = errno;
      ::unlink(pending.c_str());
      ::close(fd);
      errno = saved;
      ThrowIo(pending, "cannot write the commit journal");
    }
    done += static_cast<size_t>(w);
  }
  if (::fsync(fd) != 0) {
    const int saved = errno;
    ::unlink(pending.c_str());
    ::close(fd);
    errno = saved;
    ThrowIo(pending, "cannot flush the commit journal");
  }
  return fd;
}

}  // namespace

size_t CommitOutputTransaction() {
  Transaction& tx = Tx();
  std::lock_guard<std::mutex> lock(tx.mutex);
  size_t replaced = 0;
  if (!tx.order.empty()) {
    const long pid = static_cast<long>(::getpid());
    const std::vector<std::filesystem::path> dirs = FoldersOf(tx.order);
    const std::string name = JournalName(pid);
    // Every staged file was flushed when it was staged. With more than one file, a journal
    // listing every target goes into every folder of the set: first pending (locked, written,
    // flushed) in all of them, then named in all of them; the first name is the commit point.
    std::vector<int> fds;
    auto close_all = [&] {
      for (int fd : fds) ::close(fd);
    };
    if (tx.order.size() > 1) {
      std::string text;
      for (const auto& t : tx.order) text += t.string() + "\n";
      try {
        for (const auto& dir : dirs) fds.push_back(WritePendingJournal(dir / (name + TempSuffix(pid)), text));
        for (const auto& dir : dirs) SyncFolder(dir);
        for (const auto& dir : dirs) RenameOver(dir / (name + TempSuffix(pid)), dir / name);
      } catch (...) {
        for (const auto& dir : dirs) {
          ::unlink((dir / name).c_str());
          ::unlink((dir / (name + TempSuffix(pid))).c_str());
        }
        close_all();
        throw;
      }
      for (const auto& dir : dirs) SyncFolder(dir);
    }
    // The renames, with no other I/O between them (a reader that finds the journal waits on
    // its lock; tests/cli/test_kill.py slows this loop down with SKYBAKE_TEST_SLOW_COMMIT_MS).
    int slow_ms = 0;
    if (const char* slow = std::getenv("SKYBAKE_TEST_SLOW_COMMIT_MS")) slow_ms = std::atoi(slow);
    try {
      for (const auto& target : tx.order) {
        RenameOver(tx.staged.at(target), target);
        ++replaced;
        if (slow_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(slow_ms));
      }
    } catch (...) {
      close_all();  // the journal stays: the next reader or run completes the set
      throw;
    }
    for (const auto& dir : dirs) SyncFolder(dir);
    for (const auto& dir : dirs) ::unlink((dir / name).c_str());
    close_all();
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
