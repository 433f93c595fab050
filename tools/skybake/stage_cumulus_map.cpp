// cumulus-map edges: one cumulus map per listed time and one coverage texture (docs/clouds.md).
//
//   clouds:
//     noise: [...]                     # read by the noise-gen stage
//     cumulus: clouds/cumulus.yaml     # weather field + map layout
//     cumulus_times_s: [0, 600]        # one map per time (default [0]); a consistent sequence
//     coverage: clouds/coverage.yaml   # cloud types -> coverage texture
//
// This stage owns the `clouds` section's shape and its unknown-key report. Map edges depend on
// cumulus.yaml only and the coverage edge on coverage.yaml only, so neither rebuilds the noise
// volumes (nor each other). The YAML files are regeneration inputs (see stage_noise_gen.cpp).
#include <set>

#include "paths.h"
#include "stage.h"

namespace skybake {

namespace {

class CumulusMapStage : public Stage {
 public:
  std::string tool() const override { return "cumulus-map"; }

  void ParseConfig(YamlMap& root) override {
    std::optional<YamlMap> clouds = root.OptionalMap("clouds");
    if (!clouds) return;
    clouds->Known({"noise"});
    if (std::optional<std::filesystem::path> p = clouds->OptionalPath("cumulus")) {
      cumulus_ = std::filesystem::absolute(*p).lexically_normal();
    }
    if (std::optional<std::filesystem::path> p = clouds->OptionalPath("coverage")) {
      coverage_ = std::filesystem::absolute(*p).lexically_normal();
    }
    if (std::optional<YamlNode> times = clouds->Get("cumulus_times_s")) {
      std::optional<std::vector<double>> t = times->ToNumberList(NumberSpec::Any("s"));
      if (t) {
        times_.clear();
        std::set<std::string> seen;
        for (double v : *t) {
          if (!seen.insert(FormatExact(v)).second) times->Error("time " + FormatExact(v) + " s is listed twice");
          times_.push_back(v);
        }
      }
      if (!cumulus_) times->Error("cumulus_times_s needs 'cumulus' (the weather file)");
    }
    clouds->Finish();
  }

  void EmitRules(GenContext& ctx) const override { ctx.ninja().Rule(ToolRule(ctx, "cumulus_map", tool(), "")); }

  void EmitEdges(GenContext& ctx) const override {
    if (cumulus_) {
      ctx.AddRegenInput(*cumulus_);
      for (double t : times_) {
        const std::string ts = FormatExact(t);
        NinjaBuild b;
        b.outputs = {paths::CumulusMap(ts, ".ktx2").generic_string()};
        const std::string exr = paths::CumulusMap(ts, ".exr").generic_string();
        const std::string png = paths::CumulusMap(ts, ".png").generic_string();
        b.implicit_outputs = {exr, png};
        b.rule = "cumulus_map";
        b.inputs = {ctx.Rel(*cumulus_)};
        b.implicit_inputs = {ctx.ToolPath(tool())};
        b.variables = {{"args", "--time-s " + ts + " --exr " + exr + " --preview " + png}};
        ctx.Build(tool(), b);
      }
    }
    if (coverage_) {
      ctx.AddRegenInput(*coverage_);
      NinjaBuild b;
      b.outputs = {paths::CoverageTexture(".ktx2").generic_string()};
      const std::string exr = paths::CoverageTexture(".exr").generic_string();
      const std::string png = paths::CoverageTexture(".png").generic_string();
      b.implicit_outputs = {exr, png};
      b.rule = "cumulus_map";
      b.inputs = {ctx.Rel(*coverage_)};
      b.implicit_inputs = {ctx.ToolPath(tool())};
      b.variables = {{"args", "--product coverage --exr " + exr + " --preview " + png}};
      ctx.Build(tool(), b);
    }
  }

 private:
  std::optional<std::filesystem::path> cumulus_, coverage_;  // absolute
  std::vector<double> times_{0.0};
};

}  // namespace

std::unique_ptr<Stage> MakeCumulusMapStage() { return std::make_unique<CumulusMapStage>(); }

}  // namespace skybake
