// io/progress_log.h: the progress lines of a tool come at the intervals it is given, on a
// simulated clock (no waiting, no timing of the machine).
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "io/progress_log.h"

namespace skybake {
namespace {

using Clock = ProgressLog::Clock;

struct Line {
  double t_s;
  std::string text;
};

Clock::time_point At(Clock::time_point t0, double s) {
  return t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

// A run of `run_s` seconds: the library reports progress only at its start (the worst case, a
// stage with no intermediate calls), the ticker ticks every quarter interval as ToolCli's does.
struct Simulation {
  std::vector<Line> err, chan;
  Simulation(double stderr_interval_s, double channel_interval_s, double run_s, bool quiet = false) {
    const Clock::time_point t0 = Clock::now();
    double now = 0.0;
    ProgressLog::Options o{"tool", "tool out.exr", stderr_interval_s, channel_interval_s};
    ProgressLog::Sink e = [&](const std::string& l) { err.push_back({now, l}); };
    ProgressLog::Sink c = [&](const std::string& l) { chan.push_back({now, l}); };
    ProgressLog log(o, quiet ? ProgressLog::Sink() : e, c, t0);
    const double tick = log.TickPeriodSeconds();
    log.Report("render", 0.0, At(t0, now));
    for (int i = 1; now < run_s; ++i) {
      now = i * tick;
      log.Tick(At(t0, now));
    }
  }
};

TEST(ProgressLog, StderrHeartbeatAtTheGivenInterval) {
  const Simulation s(0.1, 5.0, 2.0);
  ASSERT_GE(s.err.size(), 20u);
  EXPECT_EQ(s.err.front().text, "tool: render 0%");
  EXPECT_DOUBLE_EQ(s.err.front().t_s, 0.0);
  for (size_t i = 1; i < s.err.size(); ++i) {
    const double gap = s.err[i].t_s - s.err[i - 1].t_s;
    EXPECT_GE(gap, 0.1 - 1e-9) << i;
    EXPECT_LE(gap, 0.1 + 0.025 + 1e-9) << i;  // at most one tick late
    EXPECT_EQ(s.err[i].text, "tool: render 0%");
  }
}

TEST(ProgressLog, ChannelLinesStartAfterOneIntervalAndNameTheOutput) {
  const Simulation s(1.0, 0.5, 2.0);
  ASSERT_EQ(s.chan.size(), 4u);  // 0.5, 1.0, 1.5, 2.0 s: none before the first interval
  for (size_t i = 0; i < s.chan.size(); ++i) {
    EXPECT_NEAR(s.chan[i].t_s, 0.5 * (i + 1), 1e-9);
    EXPECT_EQ(s.chan[i].text.rfind("tool out.exr: render 0% (", 0), 0u) << s.chan[i].text;
  }
  EXPECT_EQ(s.chan[1].text, "tool out.exr: render 0% (1.0 s)");
  // A run shorter than the interval writes nothing to the channel.
  EXPECT_TRUE(Simulation(1.0, 5.0, 4.0).chan.empty());
}

TEST(ProgressLog, QuietSilencesStderrOnly) {
  const Simulation s(0.1, 0.5, 1.0, /*quiet=*/true);
  EXPECT_TRUE(s.err.empty());
  EXPECT_EQ(s.chan.size(), 2u);
}

TEST(ProgressLog, ReportsAreRateLimitedExceptNewStagesAndEnds) {
  const Clock::time_point t0 = Clock::now();
  std::vector<std::string> err, chan;
  ProgressLog log({"tool", "tool o", 1.0, 5.0}, [&](const std::string& l) { err.push_back(l); },
                  [&](const std::string& l) { chan.push_back(l); }, t0);
  log.Report("a", 0.0, At(t0, 0.0));
  log.Report("a", 0.3, At(t0, 0.5));   // within the interval: dropped
  log.Report("a", 0.6, At(t0, 1.0));   // one interval later: printed
  log.Report("a", 1.0, At(t0, 1.1));   // the stage's end: printed
  log.Report("b", 0.0, At(t0, 1.2));   // a new stage: printed
  log.Tick(At(t0, 1.5));               // 0.3 s after the last line: nothing
  log.Tick(At(t0, 2.3));               // 1.1 s after: the heartbeat
  EXPECT_EQ(err, (std::vector<std::string>{"tool: a 0%", "tool: a 60%", "tool: a 100%", "tool: b 0%", "tool: b 0%"}));
  log.Tick(At(t0, 5.0));
  EXPECT_EQ(chan, (std::vector<std::string>{"tool o: b 0% (5.0 s)"}));
}

TEST(ProgressLog, ChannelSaysRunningBeforeTheFirstStage) {
  const Clock::time_point t0 = Clock::now();
  std::vector<std::string> err, chan;
  ProgressLog log({"tool", "tool o", 1.0, 0.5}, [&](const std::string& l) { err.push_back(l); },
                  [&](const std::string& l) { chan.push_back(l); }, t0);
  log.Tick(At(t0, 0.6));
  EXPECT_EQ(chan, (std::vector<std::string>{"tool o: running (0.6 s)"}));
  EXPECT_TRUE(err.empty());  // no stage, no stderr heartbeat
  EXPECT_DOUBLE_EQ(log.TickPeriodSeconds(), 0.125);
}

}  // namespace
}  // namespace skybake
