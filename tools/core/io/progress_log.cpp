#include "io/progress_log.h"

#include <fmt/format.h>

#include <algorithm>

namespace skybake {

ProgressLog::ProgressLog(Options options, Sink stderr_sink, Sink channel_sink, Clock::time_point start)
    : options_(std::move(options)), stderr_(std::move(stderr_sink)), channel_(std::move(channel_sink)), start_(start) {}

std::string ProgressLog::StderrLine() const {
  return fmt::format("{}: {} {:.0f}%", options_.tool, stage_, 100.0 * std::clamp(fraction_, 0.0, 1.0));
}

void ProgressLog::Report(std::string_view stage, double fraction, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool new_stage = !has_stage_ || stage != stage_;
  has_stage_ = true;
  stage_ = std::string(stage);
  fraction_ = fraction;
  if (!stderr_) return;
  if (!new_stage && fraction < 1.0 && stderr_printed_ && Seconds(now - last_stderr_) < options_.stderr_interval_s) {
    return;
  }
  last_stderr_ = now;
  stderr_printed_ = true;
  stderr_(StderrLine());
}

void ProgressLog::Tick(Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stderr_ && has_stage_ && Seconds(now - last_stderr_) >= options_.stderr_interval_s) {
    last_stderr_ = now;
    stderr_printed_ = true;
    stderr_(StderrLine());
  }
  const double elapsed = Seconds(now - start_);
  const double since = Seconds(now - (last_channel_ == Clock::time_point{} ? start_ : last_channel_));
  if (channel_ && elapsed >= options_.channel_interval_s && since >= options_.channel_interval_s) {
    last_channel_ = now;
    const std::string what =
        has_stage_ ? fmt::format("{} {:.0f}%", stage_, 100.0 * std::clamp(fraction_, 0.0, 1.0)) : std::string("running");
    channel_(fmt::format("{}: {} ({:.1f} s)", options_.label, what, elapsed));
  }
}

double ProgressLog::TickPeriodSeconds() const {
  double period = 0.0;
  if (stderr_) period = options_.stderr_interval_s;
  if (channel_) period = period > 0.0 ? std::min(period, options_.channel_interval_s) : options_.channel_interval_s;
  return period / 4.0;
}

}  // namespace skybake
