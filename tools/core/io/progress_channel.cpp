#include "io/progress_channel.h"

#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <system_error>
#include <vector>

namespace skybake {

ProgressChannelWriter::ProgressChannelWriter() {
  const char* path = std::getenv(kProgressChannelEnv);
  if (!path || !*path) return;
  // Non-blocking: open fails with ENXIO instead of waiting when no reader has the FIFO open.
  const int fd = ::open(path, O_WRONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return;
  struct stat st{};
  if (::fstat(fd, &st) != 0 || !S_ISFIFO(st.st_mode)) {  // never append to a regular file
    ::close(fd);
    return;
  }
  fd_ = fd;
}

ProgressChannelWriter::~ProgressChannelWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void ProgressChannelWriter::BlockSigpipeInThisThread() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

void ProgressChannelWriter::Write(const std::string& line) {
  if (fd_ < 0) return;
  std::string text = line.substr(0, PIPE_BUF - 1) + "\n";
  const ssize_t n = ::write(fd_, text.data(), text.size());
  if (n >= 0 || errno == EAGAIN) return;  // written whole (<= PIPE_BUF), or the FIFO is full: dropped
  if (errno == EPIPE) {
    // The reader is gone. The SIGPIPE this write raised is pending on this thread (blocked):
    // take it, so that it is never delivered.
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGPIPE);
    const timespec zero{0, 0};
    sigtimedwait(&set, nullptr, &zero);
  }
  ::close(fd_);
  fd_ = -1;
}

ProgressRelay::ProgressRelay(std::function<void(const std::string&)> on_line) : on_line_(std::move(on_line)) {
  const char* tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/skybake-progress-XXXXXX";
  std::vector<char> buf(templ.begin(), templ.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data())) {
    throw std::filesystem::filesystem_error("cannot create the progress folder", templ,
                                            std::error_code(errno, std::generic_category()));
  }
  dir_ = buf.data();
  fifo_ = dir_ / "progress";
  if (::mkfifo(fifo_.c_str(), 0600) != 0) {
    const int e = errno;
    std::filesystem::remove(dir_);
    throw std::filesystem::filesystem_error("cannot create the progress FIFO", fifo_, std::error_code(e, std::generic_category()));
  }
  // Read-write: the relay is a writer itself, so reads never see end-of-file between commands.
  fd_ = ::open(fifo_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int e = errno;
    std::filesystem::remove_all(dir_);
    throw std::filesystem::filesystem_error("cannot open the progress FIFO", fifo_, std::error_code(e, std::generic_category()));
  }
  thread_ = std::thread([this] { Run(); });
}

ProgressRelay::~ProgressRelay() { Stop(); }

void ProgressRelay::Run() {
  std::string pending;
  char chunk[4096];
  for (;;) {
    const bool last = stop_.load();
    pollfd p{fd_, POLLIN, 0};
    if (!last) ::poll(&p, 1, 100);
    // Read everything there is now (the last pass drains the FIFO).
    for (;;) {
      const ssize_t n = ::read(fd_, chunk, sizeof(chunk));
      if (n <= 0) break;
      pending.append(chunk, static_cast<size_t>(n));
    }
    size_t start = 0;
    for (size_t nl; (nl = pending.find('\n', start)) != std::string::npos; start = nl + 1) {
      on_line_(pending.substr(start, nl - start));
    }
    pending.erase(0, start);
    if (last) return;
  }
}

void ProgressRelay::Stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  thread_.join();
  ::close(fd_);
  fd_ = -1;
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

}  // namespace skybake
