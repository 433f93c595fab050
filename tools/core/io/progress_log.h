// A tool's progress lines (io/cli.h): what ToolCli prints for the ProgressFn calls of the
// library, and the heartbeat that keeps a long run visible.
//
// Two sinks, each with its own interval:
//   stderr    "<tool>: <stage> <percent>%" for a new stage, a stage's end (fraction 1) and
//             otherwise at most one per `stderr_interval_s`; while a stage is open and nothing
//             was printed for `stderr_interval_s`, the last state again (the heartbeat). None
//             under --quiet.
//   channel   the bake's progress channel (docs/pipeline.md, "Progress"): Ninja buffers a
//             command's output until it ends, so `skybake bake` gives every tool a FIFO to
//             write to and relays its lines at once. One line per `channel_interval_s`, the
//             first one `channel_interval_s` after the start (a short run writes none):
//             "<tool> <output>: <stage> <percent>% (<elapsed> s)", or "<tool> <output>:
//             running (<elapsed> s)" before the first stage. Written from Tick only.
// Every method takes the time it is called at, so the intervals are testable without waiting
// (tests/io/progress_log_test.cpp); ToolCli calls Tick from a ticker thread every quarter of
// the shorter interval. Thread-safe.
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>

namespace skybake {

class ProgressLog {
 public:
  using Clock = std::chrono::steady_clock;
  using Sink = std::function<void(const std::string& line)>;

  struct Options {
    std::string tool;           // "<tool>" of the stderr lines
    std::string label;          // "<tool> <output>" of the channel lines
    double stderr_interval_s = 1.0;
    double channel_interval_s = 5.0;
  };

  // An empty sink is off (--quiet: no stderr sink; no channel outside a bake).
  ProgressLog(Options options, Sink stderr_sink, Sink channel_sink, Clock::time_point start);

  // The library's ProgressFn call: stage name and fraction done in [0, 1].
  void Report(std::string_view stage, double fraction, Clock::time_point now);
  // The heartbeat of both sinks.
  void Tick(Clock::time_point now);

  // How often the ticker should call Tick (a quarter of the shorter active interval), seconds;
  // 0 when neither sink is on.
  double TickPeriodSeconds() const;

 private:
  std::string StderrLine() const;
  static double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  Options options_;
  Sink stderr_, channel_;
  Clock::time_point start_;
  std::mutex mutex_;
  bool has_stage_ = false;
  std::string stage_;
  double fraction_ = 0.0;
  Clock::time_point last_stderr_{}, last_channel_{};
  bool stderr_printed_ = false;
};

}  // namespace skybake
