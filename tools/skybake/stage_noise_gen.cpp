// noise-gen edges: one per volume recipe listed in pipeline.yaml `clouds.noise` (docs/clouds.md).
//
//   clouds:
//     noise: [clouds/noise_low.yaml, clouds/noise_high.yaml, ...]   # paths relative to pipeline.yaml
//
// Each edge reads only its own recipe, so an edit to one volume (or to the cumulus settings)
// re-runs only that edge. The recipes are not parsed here (noise-gen validates them with
// file:line); they are regeneration inputs so that a deleted or renamed recipe regenerates and
// is reported against pipeline.yaml instead of failing inside ninja.
#include <cctype>
#include <set>

#include "paths.h"
#include "stage.h"

namespace skybake {

namespace {

bool IsVolumeName(const std::string& s) {
  if (s.empty() || !std::islower(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s) {
    if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_')) return false;
  }
  return true;
}

class NoiseGenStage : public Stage {
 public:
  std::string tool() const override { return "noise-gen"; }

  void ParseConfig(YamlMap& root) override {
    // The `clouds` section is shared with the cumulus-map stage, which reports its shape and
    // unknown keys; this stage only reads `noise`.
    // Reading the raw node (not a second YamlMap view) keeps duplicate-key reports single.
    std::optional<YamlNode> clouds = root.Get("clouds");
    if (!clouds || !clouds->IsMap()) return;
    const YAML::Node raw = static_cast<const YAML::Node&>(clouds->raw())["noise"];
    if (!raw) return;
    const YamlNode noise = clouds->Child(raw, "clouds.noise", clouds->line());
    std::set<std::string> names;
    for (const YamlNode& f : noise.Elements("a list of volume recipe files")) {
      std::optional<std::filesystem::path> path = f.ToPath();
      if (!path) continue;
      const std::string name = path->stem().string();
      if (!IsVolumeName(name)) {
        f.Error("a volume file name must be a lowercase identifier (a-z, 0-9, _) with .yaml: it names the outputs");
        continue;
      }
      if (!names.insert(name).second) {
        f.Error("two volume files are named '" + name + "'");
        continue;
      }
      volumes_.push_back({name, std::filesystem::absolute(*path).lexically_normal()});
    }
  }

  void EmitRules(GenContext& ctx) const override { ctx.ninja().Rule(ToolRule(ctx, "noise_gen", tool(), "")); }

  void EmitEdges(GenContext& ctx) const override {
    for (const Volume& v : volumes_) {
      ctx.AddRegenInput(v.recipe);
      NinjaBuild b;
      b.outputs = {paths::CloudNoise(v.name, ".ktx2").generic_string()};
      const std::string exr = paths::CloudNoise(v.name, ".exr").generic_string();
      const std::string png = paths::CloudNoise(v.name, ".png").generic_string();
      b.implicit_outputs = {exr, png};
      b.rule = "noise_gen";
      b.inputs = {ctx.Rel(v.recipe)};
      b.implicit_inputs = {ctx.ToolPath(tool())};
      b.variables = {{"args", "--exr " + exr + " --preview " + png}};
      ctx.Build(tool(), b);
    }
  }

 private:
  struct Volume {
    std::string name;
    std::filesystem::path recipe;  // absolute
  };
  std::vector<Volume> volumes_;
};

}  // namespace

std::unique_ptr<Stage> MakeNoiseGenStage() { return std::make_unique<NoiseGenStage>(); }

}  // namespace skybake
