// The bake's progress channel: how a tool run by Ninja reports progress while it runs.
//
// Ninja buffers each command's stdout and stderr until the command ends (the `console` pool
// alone streams, and it runs one command at a time), so a tool's own progress lines reach the
// log only when they are no longer news. `skybake bake` therefore creates a FIFO, names it in
// the environment of ninja (and so of every command ninja runs), and relays every line written
// to it onto its own stdout as it arrives:
//   SKYBAKE_PROGRESS            path of the FIFO
//   SKYBAKE_PROGRESS_INTERVAL   seconds between a tool's lines (io/progress_log.h)
// Lines are written with one write() each, shorter than PIPE_BUF, so lines of parallel
// commands never interleave (POSIX write(), "Pipes and FIFOs"). The channel never slows or
// fails a tool: the FIFO is opened and written without blocking, a full FIFO drops the line,
// a missing reader (ENXIO, EPIPE) closes the channel, and SIGPIPE is blocked in the one thread
// that writes. A tool started through a launcher on another machine finds no reader there and
// writes nothing. Progress never reaches an output file.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>

namespace skybake {

inline constexpr const char* kProgressChannelEnv = "SKYBAKE_PROGRESS";
inline constexpr const char* kProgressIntervalEnv = "SKYBAKE_PROGRESS_INTERVAL";

// The tool's end: opens $SKYBAKE_PROGRESS if it is set and a reader has it open.
class ProgressChannelWriter {
 public:
  ProgressChannelWriter();
  ~ProgressChannelWriter();
  ProgressChannelWriter(const ProgressChannelWriter&) = delete;
  ProgressChannelWriter& operator=(const ProgressChannelWriter&) = delete;

  bool open() const { return fd_ >= 0; }
  // Writes `line` and a newline (truncated to fit one atomic write). Call from one thread,
  // which must block SIGPIPE (BlockSigpipeInThisThread).
  void Write(const std::string& line);

  static void BlockSigpipeInThisThread();

 private:
  int fd_ = -1;
};

// skybake's end: a FIFO in a private temporary folder and a thread that hands each complete
// line to `on_line` (called on that thread) until Stop().
class ProgressRelay {
 public:
  explicit ProgressRelay(std::function<void(const std::string&)> on_line);
  ~ProgressRelay();  // Stop()
  ProgressRelay(const ProgressRelay&) = delete;
  ProgressRelay& operator=(const ProgressRelay&) = delete;

  const std::filesystem::path& fifo() const { return fifo_; }
  // Relays what is still in the FIFO, ends the thread and removes the FIFO and its folder.
  void Stop();

 private:
  void Run();

  std::function<void(const std::string&)> on_line_;
  std::filesystem::path dir_, fifo_;
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace skybake
