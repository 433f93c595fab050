// The one command-line contract of every skybake tool (docs/developing.md, "CLI contract (every
// tool)"):
//   --help            usage on stdout, exit 0
//   --version         "<tool> (skybake) <version>" on stdout, exit 0
//   --threads N       worker threads (0 = all cores); outputs do not depend on N
//   --quiet           no progress lines on stderr
//   --progress-interval S   seconds between progress lines (default 1)
//   usage errors      "<tool>: <message>" + a hint on stderr, exit 2
//   bad input         "<tool>: file:line: message" on stderr (one line per problem), exit 1,
//                     and no output written
//   internal errors   "<tool>: internal error: ..." on stderr, exit 3
//   progress          "<tool>: <stage> <percent>%" lines on stderr: for a new stage, at a stage's
//                     end, otherwise at most one per --progress-interval, and the last state again
//                     when nothing was printed for that long (io/progress_log.h); inside a bake
//                     also heartbeat lines to the bake's progress channel (io/progress_channel.h)
//
// A tool's main builds a ToolCli, adds its options and subcommands to app(), and calls
// Run(argc, argv, body); everything the body throws is mapped to the codes above.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>

#include "io/progress.h"

namespace skybake {

class ToolCli {
 public:
  ToolCli(std::string name, std::string summary);
  ~ToolCli();

  CLI::App& app() { return app_; }
  const std::string& name() const { return name_; }
  int threads() const { return threads_; }
  bool quiet() const { return quiet_; }

  // Parses argv, sets up threads and logging, runs `body`; returns the process exit code.
  int Run(int argc, char** argv, const std::function<void()>& body);

  // A thread-safe progress callback printing rate-limited lines on stderr (and to the bake's
  // progress channel). Valid inside Run's body.
  ProgressFn Progress();
  // An informational line on stderr ("<tool>: message"), unless --quiet.
  void Info(const std::string& message);

 private:
  void StartProgress();

  std::string name_;
  CLI::App app_;
  int threads_ = 0;
  bool quiet_ = false;
  double progress_interval_s_ = 1.0;
  struct ProgressState;
  std::shared_ptr<ProgressState> progress_;
};

}  // namespace skybake
