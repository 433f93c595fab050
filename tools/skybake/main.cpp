// skybake: turns pipeline.yaml into a Ninja graph and bakes it.
//
//   skybake generate [pipeline.yaml]        write outputs/build.ninja (+ canonical components)
//   skybake bake [pipeline.yaml] [-j N] [--progress-interval S] [-- NINJA_ARGS...]
//                                           generate, then run ninja (the default targets),
//                                           relaying the tools' progress lines (io/progress_channel.h)
//   skybake validate [pipeline.yaml] [-j N] [--progress-interval S] [-- NINJA_ARGS...]
//                                           the same for ninja's `validate` target: the
//                                           path-traced references (docs/pipeline.md)
//   skybake graph [pipeline.yaml]           print the plan (tools, inputs, outputs); writes nothing
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>

#include "generator.h"
#include "io/cli.h"
#include "io/error.h"
#include "io/fileio.h"
#include "io/progress_channel.h"
#include "io/yaml.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {
fs::path ToolsDir() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InternalError("cannot locate the skybake binary: " + ec.message());
  return exe.parent_path();
}
}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("skybake",
              "Generates the Ninja graph of a skybake pipeline (pipeline.yaml) and bakes it.\n"
              "Only what an edit touches is rebuilt. See docs/pipeline.md.");
  cli.app().require_subcommand(1);
  cli.app().fallthrough();  // --threads/--quiet may follow the subcommand name
  std::string pipeline = "pipeline.yaml";
  CLI::App* gen = cli.app().add_subcommand("generate", "Write <outputs>/build.ninja and the canonical components");
  gen->add_option("pipeline", pipeline, "Pipeline file")->capture_default_str();
  int jobs = 0;
  double relay_interval_s = 5.0;
  std::vector<std::string> ninja_args;
  auto ninja_options = [&](CLI::App* sub) {
    sub->add_option("pipeline", pipeline, "Pipeline file")->capture_default_str();
    sub->add_option("-j,--jobs", jobs, "Parallel ninja jobs (default: ninja's choice)")->check(CLI::NonNegativeNumber);
    sub->add_option("--progress-interval", relay_interval_s,
                    "Seconds between the progress lines of each running tool, 0.01 to 3600 (default 5)")
        ->check(CLI::Range(0.01, 3600.0));
    sub->add_option("ninja_args", ninja_args, "Extra arguments for ninja (after --)");
  };
  CLI::App* bake = cli.app().add_subcommand("bake", "Generate, then run ninja in the outputs folder");
  ninja_options(bake);
  CLI::App* validate = cli.app().add_subcommand(
      "validate", "Generate, then build the path-traced references (ninja's 'validate' target)");
  ninja_options(validate);
  CLI::App* graph = cli.app().add_subcommand("graph", "Print the plan (tools, inputs, outputs) without writing anything");
  graph->add_option("pipeline", pipeline, "Pipeline file")->capture_default_str();

  int exit_code = 0;
  int rc = cli.Run(argc, argv, [&] {
    const bool dry = graph->parsed();
    GenerateResult r = Generate(pipeline, ToolsDir(), dry);
    if (graph->parsed()) {
      for (const PlannedEdge& e : r.plan) {
        std::cout << e.tool << ":";
        for (const auto& o : e.outputs) std::cout << " " << o;
        std::cout << "\n";
        for (const auto& i : e.inputs) std::cout << "    <- " << i << "\n";
      }
      return;
    }
    cli.Info(std::string(r.changed ? "wrote " : "unchanged ") + r.build_ninja.string());
    if (!bake->parsed() && !validate->parsed()) return;
    CommitOutputTransaction();  // ninja reads build.ninja and the components from disk
    // A tool killed after its commit point left a journal; complete every one under the outputs
    // folder, so that ninja (which reads the products' mtimes and depfiles) sees complete sets.
    RecoverOutputTree(r.build_ninja.parent_path());
    std::vector<std::string> args = {"ninja", "-C", r.build_ninja.parent_path().string()};
    if (jobs > 0) args.push_back("-j" + std::to_string(jobs));
    args.insert(args.end(), ninja_args.begin(), ninja_args.end());
    if (validate->parsed()) args.push_back("validate");
    // The progress channel: every line a tool writes to the FIFO goes to stdout at once (ninja
    // holds the tools' own output until each command ends). On a terminal ninja keeps its status
    // on one line that it rewrites; a relayed line clears it first and ends with a newline.
    const bool tty = isatty(STDOUT_FILENO) != 0;
    std::mutex out_mutex;
    ProgressRelay relay([&](const std::string& line) {
      std::lock_guard<std::mutex> lock(out_mutex);
      std::cout << (tty ? "\r\x1b[K" : "") << line << std::endl;
    });
    setenv(kProgressChannelEnv, relay.fifo().c_str(), 1);
    const std::string interval = FormatExact(relay_interval_s);
    setenv(kProgressIntervalEnv, interval.c_str(), 1);
    std::vector<char*> cargs;
    for (auto& a : args) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    std::cout.flush();
    pid_t pid = fork();
    if (pid == 0) {
      execvp("ninja", cargs.data());
      std::cerr << "skybake: cannot run ninja (is ninja-build installed?)\n";
      _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    relay.Stop();
    exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  });
  return rc != 0 ? rc : exit_code;
}
