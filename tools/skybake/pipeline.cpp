#include "pipeline.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "io/yaml.h"
#include "stage.h"

namespace fs = std::filesystem;

namespace skybake {

std::vector<double> PipelineWavelengths::Values() const {
  std::vector<double> v;
  const size_t n = static_cast<size_t>(std::llround((max_nm - min_nm) / step_nm));
  for (size_t i = 0; i <= n; ++i) v.push_back(min_nm + static_cast<double>(i) * step_nm);
  return v;
}

namespace {

// The launcher's command (its first word) as Ninja's shell will find it: a path (relative to the
// outputs folder, where ninja runs) or a name on PATH. Returns what is wrong, or nullopt.
std::optional<std::string> MissingLauncher(const std::string& prefix, const fs::path& out_dir) {
  const size_t begin = prefix.find_first_not_of(" \t");
  if (begin == std::string::npos) return std::nullopt;  // an empty prefix runs the tool itself
  const std::string command = prefix.substr(begin, prefix.find_first_of(" \t", begin) - begin);
  auto runnable = [](const fs::path& f) { return access(f.c_str(), X_OK) == 0 && !fs::is_directory(f); };
  if (command.find('/') != std::string::npos) {
    const fs::path f = fs::path(command).is_absolute() ? fs::path(command) : out_dir / command;
    if (runnable(f)) return std::nullopt;
    return "'" + command + "' is not an executable file";
  }
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  for (size_t at = 0; at <= dirs.size();) {
    const size_t end = std::min(dirs.find(':', at), dirs.size());
    const std::string dir = dirs.substr(at, end - at);
    if (runnable(fs::path(dir.empty() ? "." : dir) / command)) return std::nullopt;
    at = end + 1;
  }
  return "'" + command + "' is not on PATH: install it (e.g. Slurm's srun) where skybake generates the graph, or change the launcher";
}

}  // namespace

Pipeline LoadPipeline(const fs::path& path, const std::vector<Stage*>& stages) {
  Pipeline p;
  p.file = fs::absolute(path).lexically_normal();
  p.root_dir = p.file.parent_path();
  YamlDocument doc = YamlDocument::Load(p.file);
  p.files_read.push_back(p.file);
  YamlMap root = doc.RootMap();

  p.out_dir = (p.root_dir / root.OptionalString("outputs", "a folder path").value_or("outputs")).lexically_normal();
  p.altitude_step_m = root.NumberOr("altitude_step_m", NumberSpec::Range(1.0, 10000.0, "m"), 100.0);
  if (std::optional<YamlMap> wl = root.OptionalMap("wavelengths")) {
    p.wavelengths.min_nm = wl->NumberOr("min_nm", NumberSpec::Range(200.0, 3000.0, "nm"), 360.0);
    p.wavelengths.max_nm = wl->NumberOr("max_nm", NumberSpec::Range(200.0, 3000.0, "nm"), 830.0);
    p.wavelengths.step_nm = wl->NumberOr("step_nm", NumberSpec::Positive("nm"), 5.0);
    if (p.wavelengths.max_nm < p.wavelengths.min_nm) {
      wl->node().Error("max_nm must not be below min_nm");
    } else {
      double n = (p.wavelengths.max_nm - p.wavelengths.min_nm) / p.wavelengths.step_nm;
      if (std::abs(n - std::round(n)) > 1e-9) wl->node().Error("(max_nm - min_nm) must be a whole number of step_nm");
    }
    wl->Finish();
  }
  if (std::optional<YamlMap> pools = root.OptionalMap("pools")) {
    // A pools value that is not a map is reported by OptionalMap (valid() false); a key that is
    // not a plain name by Finish.
    for (auto it = pools->node().raw().begin(); pools->valid() && it != pools->node().raw().end(); ++it) {
      if (!it->first.IsScalar()) continue;
      std::string name = it->first.Scalar();
      if (name == "console") {
        pools->node().Error("'console' is Ninja's built-in pool and cannot be redefined");
      }
      p.pools[name] = static_cast<int>(pools->Integer(name, 1, 1024, "a pool depth from 1 to 1024", 1));
    }
    pools->Finish();
  }
  std::vector<std::string> tool_names;
  for (Stage* s : stages) tool_names.push_back(s->tool());
  if (std::optional<YamlMap> launchers = root.OptionalMap("launchers")) {
    for (auto it = launchers->node().raw().begin(); launchers->valid() && it != launchers->node().raw().end(); ++it) {
      if (!it->first.IsScalar()) continue;
      std::string tool = it->first.Scalar();
      if (std::find(tool_names.begin(), tool_names.end(), tool) == tool_names.end()) continue;  // reported by Finish
      p.launchers[tool] = launchers->String(tool, "a command prefix");
      // A missing launcher fails here, not when ninja first runs the tool mid-bake.
      if (std::optional<std::string> missing = MissingLauncher(p.launchers[tool], p.out_dir)) {
        launchers->Get(tool)->Error(*missing);
      }
    }
    for (const auto& t : tool_names) launchers->Known({t});
    launchers->Finish();
  }

  std::vector<YamlNode> atmospheres = root.Seq("atmospheres");
  std::set<std::string> names;
  std::vector<Diagnostic> atmosphere_errors;
  for (const YamlNode& a : atmospheres) {
    std::optional<fs::path> file = a.ToPath();
    if (!file) continue;
    fs::path abs = fs::absolute(*file).lexically_normal();
    p.files_read.push_back(abs);
    try {
      PipelineAtmosphere pa;
      pa.file = abs;
      pa.spec = LoadAtmosphere(abs);
      pa.name = pa.spec.name;
      if (!IsIdentifier(pa.name)) {  // a name from the file name; a 'name:' key is checked at load
        a.Error("the atmosphere is named by its file name '" + pa.name + "', which is not " + kIdentifierExpected +
                ": rename the file or give 'name:'");
        continue;
      }
      if (!pa.spec.grid) pa.spec.grid = GridSpec{p.altitude_step_m};
      if (!names.insert(pa.name).second) {
        a.Error("two atmospheres are named '" + pa.name + "'");
      }
      p.atmospheres.push_back(std::move(pa));
    } catch (const InputError& e) {
      atmosphere_errors.insert(atmosphere_errors.end(), e.diagnostics().begin(), e.diagnostics().end());
    }
  }
  for (Stage* s : stages) s->ParseConfig(root);
  root.Finish();
  for (const Diagnostic& d : atmosphere_errors) doc.diags().Add(d.loc, d.message);
  doc.ThrowIfErrors();
  return p;
}

}  // namespace skybake
