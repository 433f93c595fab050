#include "io/cli.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>

#include "io/error.h"
#include "io/fileio.h"
#include "skybake/version.h"

namespace skybake {

struct ToolCli::ProgressState {
  std::mutex mutex;
  std::chrono::steady_clock::time_point last{};
  std::string last_stage;
  std::shared_ptr<spdlog::logger> logger;
};

ToolCli::ToolCli(std::string name, std::string summary)
    : name_(std::move(name)), app_(std::move(summary), name_), progress_(std::make_shared<ProgressState>()) {
  app_.set_version_flag("--version", name_ + " (skybake) " + kVersion, "Print the version and exit");
  app_.add_option("--threads", threads_, "Worker threads (0 = all cores); outputs are identical for any value")
      ->check(CLI::NonNegativeNumber)
      ->default_val(0);
  app_.add_flag("--quiet", quiet_, "Do not print progress lines");
  app_.failure_message([this](const CLI::App*, const CLI::Error& e) {
    return name_ + ": " + e.what() + "\n" + name_ + ": run '" + name_ + " --help' for usage\n";
  });
}

ToolCli::~ToolCli() = default;

void ToolCli::Info(const std::string& message) {
  if (quiet_) return;
  std::lock_guard<std::mutex> lock(progress_->mutex);
  progress_->logger->info("{}: {}", name_, message);
}

ProgressFn ToolCli::Progress() {
  std::shared_ptr<ProgressState> state = progress_;
  std::string name = name_;
  bool quiet = quiet_;
  return [state, name, quiet](std::string_view stage, double fraction) {
    if (quiet) return;
    std::lock_guard<std::mutex> lock(state->mutex);
    auto now = std::chrono::steady_clock::now();
    bool new_stage = stage != state->last_stage;
    if (!new_stage && fraction < 1.0 && now - state->last < std::chrono::seconds(1)) return;
    state->last = now;
    state->last_stage = std::string(stage);
    state->logger->info("{}: {} {:.0f}%", name, stage, 100.0 * std::clamp(fraction, 0.0, 1.0));
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

}  // namespace

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
    if (arena) {
      arena->execute(body);
    } else {
      body();
    }
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
