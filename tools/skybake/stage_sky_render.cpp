// sky-render edges: one render per atmosphere (docs/sky-render.md, docs/pipeline.md).
//
//   outputs/<atm>/components/render.yaml   canonical render component (written here)
//   outputs/<atm>/sky.exr, sky.png         sky-render render (+ preview)
//
// The edge depends on the render component, the atmosphere's profiles.exr, the Mie tables of
// its particle types and the tool; data tables (sun spectrum, albedo, ozone cross-section,
// CMFs, the OCIO config) come through the depfile. Settings come from pipeline.yaml's `sky`
// section:
//   sky:
//     method: path                 # the only method until sky-render part 2
//     mapping: equirectangular     # or fisheye
//     size: 32x16
//     sun_zenith_deg: [30, 70, 85, 90, 94]
//     target_error: 0.05           # relative standard error of Y per texel
//     preview: true
//     atmospheres: [clear, hazed]  # optional: only these get a reference render (default: all)
//     shards: 4                    # each render as 4 shard edges (slices x texels) + a merge
//                                  # that writes the EXR and the preview (docs/cluster.md)
//     target: validate             # default (the default bake builds the references) or
//                                  # validate (only `skybake validate` / `ninja validate` does)
// Every reference is an input of the phony target `validate` either way.
#include <fmt/format.h>

#include <map>
#include <set>

#include "atmosphere/spec.h"
#include "paths.h"
#include "shards.h"
#include "stage.h"
#include "stage_helpers.h"
#include "io/size.h"

namespace skybake {

namespace {

class SkyRenderStage : public Stage {
 public:
  std::string tool() const override { return "sky-render"; }

  void ParseConfig(YamlMap& root) override {
    std::optional<YamlMap> sky = root.OptionalMap("sky");
    if (!sky) return;
    method_ = sky->ChoiceOr("method", {"path"}, method_);
    mapping_ = sky->ChoiceOr("mapping", {"equirectangular", "fisheye"}, mapping_);
    if (std::optional<std::string> size = sky->OptionalString("size", "WxH, e.g. 32x16")) {
      if (!ParseSize(*size, 2, 8192)) {
        sky->Get("size")->ErrorExpected(SizeExpected(2, 8192, "32x16"));
      } else {
        size_ = *size;
      }
    }
    if (sky->Has("sun_zenith_deg")) sun_zenith_deg_ = sky->NumberList("sun_zenith_deg", NumberSpec::Range(0, 180, "degrees"));
    target_error_ = sky->NumberOr("target_error", NumberSpec::Range(1e-4, 1.0, ""), target_error_);
    preview_ = sky->BoolOr("preview", preview_);
    shards_ = ShardsOr(*sky, shards_);
    in_default_ = sky->ChoiceOr("target", {"default", "validate"}, "default") == "default";
    // A path render's shard task is a texel of a slice, at least one per mirror pair of texels.
    const std::optional<Size2> grid = ParseSize(size_, 2, 8192);
    const size_t tasks = sun_zenith_deg_.size() * (grid ? static_cast<size_t>(grid->width) * grid->height / 2 : 1);
    if (sky->Has("shards") && static_cast<size_t>(shards_) > tasks) {
      sky->Get("shards")->Error(fmt::format("{} shards for {} texel tasks of the render: at most one shard per task", shards_, tasks));
    }
    if (std::optional<std::vector<YamlNode>> only = sky->OptionalSeq("atmospheres")) {
      only_.emplace();
      for (const YamlNode& n : *only) {
        if (std::optional<std::string> name = n.ToString("an atmosphere name")) {
          only_->insert(*name);
          only_loc_[*name] = n.loc();
        }
      }
    }
    sky->Finish();
  }

  void EmitRules(GenContext& ctx) const override {
    const std::string pool = ctx.pipeline().pools.count("render") ? "render" : "";
    ctx.ninja().Rule(ToolRule(ctx, "sky_render", tool(), pool));
    if (shards_ > 1) ctx.ninja().Rule(ShardMergeRule(ctx, "sky_merge", tool()));
  }

  void EmitEdges(GenContext& ctx) const override {
    const auto& wl = ctx.pipeline().wavelengths;
    for (const auto& [name, loc] : only_loc_) {
      bool known = false;
      for (const PipelineAtmosphere& a : ctx.pipeline().atmospheres) known = known || a.name == name;
      if (!known) throw InputError(loc, "sky.atmospheres: '" + name + "' is not an atmosphere of this pipeline");
    }
    ctx.SetReferenceEdges(true, in_default_);
    std::string zeniths;
    for (double z : sun_zenith_deg_) zeniths += (zeniths.empty() ? "" : ",") + FormatExact(z);
    for (const PipelineAtmosphere& a : ctx.pipeline().atmospheres) {
      const std::filesystem::path comp_rel = paths::RenderComponent(a.name);
      ctx.WriteComponent(comp_rel, CanonicalRenderYaml(a.spec, (ctx.pipeline().out_dir / comp_rel).parent_path()));
      if (only_ && !only_->count(a.name)) continue;  // the component is still written: other renderers use it
      // A render needs the whole atmosphere: say so now, naming the atmosphere file, rather than
      // when ninja runs sky-render on the generated component.
      RequireSections(a.spec, {"planet", "air", "ground", "sun"});
      NinjaBuild b;
      b.outputs = {paths::Sky(a.name).generic_string()};
      if (preview_) b.implicit_outputs = {paths::SkyPreview(a.name).generic_string()};
      b.rule = "sky_render";
      b.inputs = {comp_rel.generic_string()};
      b.implicit_inputs = {ctx.ToolPath(tool()), paths::Profiles(a.name).generic_string()};
      for (const std::string& mie : MieTableInputs(a.spec)) b.implicit_inputs.push_back(mie);
      std::string args = fmt::format(
          "render --method {} --profiles {} --mie-dir mie --wavelengths {}:{}:{} --mapping {} --size {} "
          "--sun-zenith-deg {} --target-error {}",
          method_, paths::Profiles(a.name).generic_string(), FormatExact(wl.min_nm), FormatExact(wl.max_nm),
          FormatExact(wl.step_nm), mapping_, size_, zeniths, FormatExact(target_error_));
      b.variables = {{"args", args}};
      BuildSharded(ctx, tool(), b, preview_ ? " --preview " + paths::SkyPreview(a.name).generic_string() : "", shards_,
                   "sky_merge");
    }
    ctx.SetReferenceEdges(false);
  }

 private:
  std::string method_ = "path";
  std::string mapping_ = "equirectangular";
  std::string size_ = "32x16";
  std::vector<double> sun_zenith_deg_ = {30, 70, 85, 90, 94};
  double target_error_ = 0.05;
  bool preview_ = true;
  int shards_ = 1;
  bool in_default_ = true;  // sky.target
  std::optional<std::set<std::string>> only_;  // sky.atmospheres
  std::map<std::string, FileLoc> only_loc_;
};

}  // namespace

std::unique_ptr<Stage> MakeSkyRenderStage() { return std::make_unique<SkyRenderStage>(); }

}  // namespace skybake
