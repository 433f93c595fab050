#include "io/cli.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <thread>

#include "io/error.h"
#include "io/fileio.h"
#include "io/progress_channel.h"
#include "io/progress_log.h"
#include "skybake/version.h"

namespace skybake {

struct ToolCli::ProgressState {
  std::mutex mutex;  // Info lines
  std::shared_ptr<spdlog::logger> logger;
  std::unique_ptr<ProgressChannelWriter> channel;
  std::unique_ptr<ProgressLog> log;
  // The ticker thread calling log->Tick.
  std::mutex tick_mutex;
  std::condition_variable tick_wake;
  bool tick_stop = false;
  std::thread ticker;

  void StopTicker() {
    if (!ticker.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(tick_mutex);
      tick_stop = true;
    }
    tick_wake.notify_all();
    ticker.join();
  }
};

ToolCli::ToolCli(std::string name, std::string summary)
    : name_(std::move(name)), app_(std::move(summary), name_), progress_(std::make_shared<ProgressState>()) {
  app_.set_version_flag("--version", name_ + " (skybake) " + kVersion, "Print the version and exit");
  app_.add_option("--threads", threads_, "Worker threads (0 = all cores); outputs are identical for any value")
      ->check(CLI::NonNegativeNumber)
      ->default_val(0);
  app_.add_flag("--quiet", quiet_, "Do not print progress lines");
  app_.add_option("--progress-interval", progress_interval_s_,
                  "Seconds between progress lines, 0.01 to 3600 (a line at least this often while a stage runs)")
      ->check(CLI::Range(0.01, 3600.0))
      ->default_val(1.0);
  app_.failure_message([this](const CLI::App*, const CLI::Error& e) {
    return name_ + ": " + e.what() + "\n" + name_ + ": run '" + name_ + " --help' for usage\n";
  });
}

ToolCli::~ToolCli() { progress_->StopTicker(); }

void ToolCli::Info(const std::string& message) {
  if (quiet_) return;
  std::lock_guard<std::mutex> lock(progress_->mutex);
  progress_->logger->info("{}: {}", name_, message);
}

ProgressFn ToolCli::Progress() {
  std::shared_ptr<ProgressState> state = progress_;
  return [state](std::string_view stage, double fraction) {
    if (state->log) state->log->Report(stage, fraction, ProgressLog::Clock::now());
  };
}

namespace {

// CLI11's numeric validators (Range, PositiveNumber, ...) compare with < and >, which a NaN
// passes, and its double options accept "nan" and "inf": every floating-point option of the
// parsed (sub)commands is checked here to be a finite number before the tool does any work.
void CheckFiniteOptions(CLI::App* app) {
  for (CLI::Option* opt : app->get_options()) {
    if (opt->count() == 0 || opt->get_type_name().find("FLOAT") == std::string::npos) continue;
    for (const std::string& r : opt->results()) {
      char* end = nullptr;
      const double v = std::strtod(r.c_str(), &end);
      if (end != r.c_str() && !std::isfinite(v)) {
        throw UsageError(opt->get_name() + " " + r + ": expected a finite number");
      }
    }
  }
  for (CLI::App* sub : app->get_subcommands()) CheckFiniteOptions(sub);
}

// The output a command writes (its -o/--output), for the channel's label; empty if none.
std::string OutputOption(CLI::App* app) {
  for (const char* name : {"--output", "-o"}) {
    const CLI::Option* opt = app->get_option_no_throw(name);
    if (opt && opt->count() > 0) return opt->results().front();
  }
  for (CLI::App* sub : app->get_subcommands()) {
    std::string out = OutputOption(sub);
    if (!out.empty()) return out;
  }
  return {};
}

// $SKYBAKE_PROGRESS_INTERVAL: seconds, 0.01 to 3600 (default 5).
double ChannelInterval() {
  const char* text = std::getenv(kProgressIntervalEnv);
  if (!text || !*text) return 5.0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v) || v < 0.01 || v > 3600.0) {
    throw UsageError(std::string(kProgressIntervalEnv) + "=" + text + ": expected seconds from 0.01 to 3600");
  }
  return v;
}

}  // namespace

void ToolCli::StartProgress() {
  ProgressState& st = *progress_;
  const double channel_interval = ChannelInterval();
  st.channel = std::make_unique<ProgressChannelWriter>();
  ProgressLog::Options o;
  o.tool = name_;
  const std::string output = OutputOption(&app_);
  o.label = output.empty() ? name_ : name_ + " " + output;
  o.stderr_interval_s = progress_interval_s_;
  o.channel_interval_s = channel_interval;
  ProgressLog::Sink err, chan;
  if (!quiet_) {
    std::shared_ptr<spdlog::logger> logger = st.logger;
    err = [logger](const std::string& line) { logger->info("{}", line); };
  }
  if (st.channel->open()) chan = [&st](const std::string& line) { st.channel->Write(line); };
  st.log = std::make_unique<ProgressLog>(o, err, chan, ProgressLog::Clock::now());
  const double period = st.log->TickPeriodSeconds();
  if (period <= 0.0) return;
  st.ticker = std::thread([&st, period] {
    ProgressChannelWriter::BlockSigpipeInThisThread();  // the channel's writes happen here only
    std::unique_lock<std::mutex> lock(st.tick_mutex);
    while (!st.tick_stop) {
      st.tick_wake.wait_for(lock, std::chrono::duration<double>(period));
      if (st.tick_stop) break;
      lock.unlock();
      st.log->Tick(ProgressLog::Clock::now());
      lock.lock();
    }
  });
}

int ToolCli::Run(int argc, char** argv, const std::function<void()>& body) {
  // Plain stderr sink: no colours (ninja and CI logs), the tool name as prefix.
  progress_->logger = std::make_shared<spdlog::logger>(name_, std::make_shared<spdlog::sinks::stderr_sink_mt>());
  progress_->logger->set_pattern("%v");
  try {
    app_.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app_.exit(e);
    return code == 0 ? 0 : 2;
  }
  // --threads N runs the body on exactly N worker threads, also where N exceeds the cores: the
  // control lifts TBB's worker cap (the core count) to N and an arena of N slots runs the body
  // (either alone gives one thread on a one-core machine). N = 0: TBB's default, all cores.
  std::unique_ptr<tbb::global_control> threads_control;
  std::unique_ptr<tbb::task_arena> arena;
  if (threads_ > 0) {
    threads_control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            static_cast<size_t>(threads_));
    arena = std::make_unique<tbb::task_arena>(threads_);
  }
  // One output transaction per command (io/fileio.h): the body's files become visible together
  // when it succeeds, and none of them when it throws.
  struct TransactionGuard {
    bool done = false;
    TransactionGuard() { BeginOutputTransaction(); }
    ~TransactionGuard() {
      if (!done) AbortOutputTransaction();
    }
  } transaction;
  try {
    CheckFiniteOptions(&app_);
    StartProgress();
    struct TickerGuard {
      ProgressState& state;
      ~TickerGuard() { state.StopTicker(); }  // before any error line is printed
    } ticker{*progress_};
    if (arena) {
      arena->execute(body);
    } else {
      body();
    }
    progress_->StopTicker();
    CommitOutputTransaction();
    transaction.done = true;
    return 0;
  } catch (const InputError& e) {
    for (const Diagnostic& d : e.diagnostics()) std::cerr << name_ << ": " << d.ToString() << "\n";
    return 1;
  } catch (const UsageError& e) {
    std::cerr << name_ << ": " << e.what() << "\n" << name_ << ": run '" << name_ << " --help' for usage\n";
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << name_ << ": " << e.path1().string() << ": " << e.code().message() << "\n";
    return 1;
  } catch (const InternalError& e) {
    std::cerr << name_ << ": internal error: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << name_ << ": internal error: " << e.what() << "\n";
    return 3;
  }
}

}  // namespace skybake
