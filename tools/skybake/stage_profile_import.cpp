// profile-import edges: one per atmosphere, from its canonical profile component.
#include "atmosphere/spec.h"
#include "paths.h"
#include "stage.h"

namespace skybake {

namespace {

class ProfileImportStage : public Stage {
 public:
  std::string tool() const override { return "profile-import"; }

  void EmitRules(GenContext& ctx) const override {
    ctx.ninja().Rule(ToolRule(ctx, "profile_import", tool(), ""));
  }

  void EmitEdges(GenContext& ctx) const override {
    for (const PipelineAtmosphere& a : ctx.pipeline().atmospheres) {
      const std::filesystem::path comp_rel = paths::ProfilesComponent(a.name);
      const std::filesystem::path comp_abs = ctx.pipeline().out_dir / comp_rel;
      ctx.WriteComponent(comp_rel, CanonicalProfilesYaml(a.spec, comp_abs.parent_path()));
      NinjaBuild b;
      b.outputs = {paths::Profiles(a.name).generic_string()};
      b.rule = "profile_import";
      b.inputs = {comp_rel.generic_string()};
      b.implicit_inputs = {ctx.ToolPath(tool())};
      ctx.Build(tool(), b);
    }
  }
};

}  // namespace

std::unique_ptr<Stage> MakeProfileImportStage() { return std::make_unique<ProfileImportStage>(); }

}  // namespace skybake
