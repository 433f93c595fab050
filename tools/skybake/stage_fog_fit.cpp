// fog-fit edges: GT7 global fog of the basis skies (docs/fog.md; GT7 sky
// talk, "Fog").
//
//   outputs/<atm>/fog.exr             sky-render fog: the reference fog of the low atmosphere (LUT
//                                     slices, depth tables, attenuation nodes) of one basis sky
//   outputs/fog/fog_<atm>.json        fog-fit fit of that render, with beside it the sky's fog,
//   outputs/fog/fog_<atm>*.ktx2 ...   shadowed fog and attenuation LUTs, report and residual maps
//
// Only with a `fog` section in pipeline.yaml:
//   fog:
//     method: orders               # sky-render fog method (orders or path)
//     quality: low                 # orders quality preset (docs/fog.md, "Bake time")
//     spectral_stride: 4           # orders on every k-th wavelength (docs/sky-methods.md)
//     cut_altitude_km: 1           # top of the low atmosphere (docs/fog.md, "The cut")
//     time_mapping: gt7-quadratic  # GT7 time mapping of the fog LUT slices (as luts.time_mapping)
//     lut_size: 32x32              # fog LUT slice W x H (GT7: 32 x 32 x 64)
//     attenuation_size: 64x64      # attenuation LUT (GT7: 64 x 64)
//     depth_tables: {sun_zenith_deg: [...], elevations: 9, azimuths_deg: [...], depths: 16}
//     angle: path                  # the fit's normalised angle: path or elevation (the talk's)
//     channels: rgb                # a, p per channel, or one for all (luminance)
//     params: per-slice-elevation  # a, p per fog LUT slice, a per elevation too (default); per-slice; global (the talk's)
//     shards: 4                    # each render as 4 shard edges + a merge (docs/cluster.md), at
//                                  # most one shard per LUT slice and depth table
//     skies: [clear, hazed]        # atmospheres of the list above
// One render edge (or its shard edges and merge) and one fit edge per sky: an edit to one
// atmosphere re-runs only its edges (every fit writes only its own sky's files; write-if-changed + restat).
#include <fmt/format.h>

#include <set>

#include "atmosphere/spec.h"
#include "paths.h"
#include "shards.h"
#include "stage.h"
#include "stage_helpers.h"
#include "io/size.h"
#include "transport/quality.h"
#include "transport/sky_method.h"

namespace skybake {

namespace {

class FogFitStage : public Stage {
 public:
  std::string tool() const override { return "fog-fit"; }

  void ParseConfig(YamlMap& root) override {
    std::optional<YamlMap> fog = root.OptionalMap("fog");
    if (!fog) return;
    enabled_ = true;
    std::vector<std::string> methods = SegmentMethodNames();
    methods.push_back("path");
    method_ = fog->ChoiceOr("method", methods, method_);
    quality_ = QualityOr(*fog, quality_);
    stride_ = static_cast<int>(fog->IntegerOr("spectral_stride", 1, 64, "a whole number from 1 to 64", stride_));
    cut_km_ = fog->NumberOr("cut_altitude_km", NumberSpec::Range(0.001, 100.0, "km"), cut_km_);
    time_mapping_ = TimeMappingOr(*fog, time_mapping_);
    lut_size_ = Size(*fog, "lut_size", lut_size_);
    attenuation_size_ = Size(*fog, "attenuation_size", attenuation_size_);
    if (std::optional<YamlMap> t = fog->OptionalMap("depth_tables")) {
      if (t->Has("sun_zenith_deg")) sun_zenith_deg_ = t->NumberList("sun_zenith_deg", NumberSpec::Range(0, 180, "deg"));
      if (t->Has("azimuths_deg")) azimuths_deg_ = t->NumberList("azimuths_deg", NumberSpec::Range(0, 180, "deg"));
      elevations_ = static_cast<int>(t->IntegerOr("elevations", 2, 1000, "a whole number of elevations from 2 to 1000", elevations_));
      depths_ = static_cast<int>(t->IntegerOr("depths", 2, 1000, "a whole number of depths from 2 to 1000", depths_));
      if (sun_zenith_deg_.empty()) t->node().Error("fog.depth_tables.sun_zenith_deg: expected at least one angle");
      if (azimuths_deg_.empty()) t->node().Error("fog.depth_tables.azimuths_deg: expected at least one angle");
      t->Finish();
    }
    angle_ = fog->ChoiceOr("angle", {"path", "elevation"}, angle_);
    channels_ = fog->ChoiceOr("channels", {"rgb", "luminance"}, channels_);
    params_ = fog->ChoiceOr("params", {"per-slice-elevation", "per-slice", "global"}, params_);
    shards_ = ShardsOr(*fog, shards_);
    // A fog render's shard task is a LUT slice or a depth table (fog/fog_shard.h).
    const int tasks = TimeMappingSlices(time_mapping_) + static_cast<int>(sun_zenith_deg_.size());
    if (fog->Has("shards") && shards_ > tasks) {
      fog->Get("shards")->Error(fmt::format("{} shards for the {} LUT slices of time mapping {} and {} depth tables: at "
                                            "most one shard per slice or table",
                                            shards_, TimeMappingSlices(time_mapping_), time_mapping_,
                                            sun_zenith_deg_.size()));
    }
    std::set<std::string> seen;
    for (const YamlNode& n : fog->Seq("skies")) {
      const std::optional<std::string> s = n.ToString("the name of an atmosphere of the list above");
      if (!s) continue;
      if (!seen.insert(*s).second) n.Error("basis sky '" + *s + "' is listed twice");
      skies_.push_back({*s, n.loc()});
    }
    if (skies_.empty()) fog->node().Error("fog.skies: expected at least one basis sky");
    fog->Finish();
  }

  void EmitRules(GenContext& ctx) const override {
    if (!enabled_) return;
    const std::string pool = ctx.pipeline().pools.count("render") ? "render" : "";
    ctx.ninja().Rule(ToolRule(ctx, "fog_render", "sky-render", pool));
    if (shards_ > 1) ctx.ninja().Rule(ShardMergeRule(ctx, "fog_merge", "sky-render"));
    ctx.ninja().Rule(ToolRule(ctx, "fog_fit", tool(), ""));
  }

  void EmitEdges(GenContext& ctx) const override {
    if (!enabled_) return;
    const auto& wl = ctx.pipeline().wavelengths;
    Diagnostics diags;
    auto join = [](const std::vector<double>& v) {
      std::string s;
      for (double x : v) s += (s.empty() ? "" : ",") + FormatExact(x);
      return s;
    };
    for (const auto& [name, loc] : skies_) {
      const PipelineAtmosphere* a = FindAtmosphere(ctx.pipeline(), name, "fog.skies", loc, &diags);
      if (!a) continue;
      NinjaBuild r;
      r.outputs = {paths::FogRender(a->name).generic_string()};
      r.rule = "fog_render";
      r.inputs = {paths::RenderComponent(a->name).generic_string()};
      r.implicit_inputs = {ctx.ToolPath("sky-render"), paths::Profiles(a->name).generic_string()};
      for (const std::string& mie : MieTableInputs(a->spec)) r.implicit_inputs.push_back(mie);
      r.variables = {{"args", fmt::format("fog --method {} --quality {} --spectral-stride {} --profiles {} --mie-dir mie --wavelengths {}:{}:{} "
                                          "--cut-altitude-km {} --lut-size {} --time-mapping {} --attenuation-size {} "
                                          "--sun-zenith-deg {} --elevations {} --azimuths-deg {} --depths {}",
                                          method_, QualityName(quality_), stride_, paths::Profiles(a->name).generic_string(),
                                          FormatExact(wl.min_nm), FormatExact(wl.max_nm), FormatExact(wl.step_nm),
                                          FormatExact(cut_km_), lut_size_, time_mapping_, attenuation_size_,
                                          join(sun_zenith_deg_), elevations_, join(azimuths_deg_), depths_)}};
      BuildSharded(ctx, "sky-render", r, "", shards_, "fog_merge");

      NinjaBuild f;
      f.outputs = {paths::FogParams(a->name).generic_string()};
      for (const std::string& file : paths::FogSkyFiles(a->name)) f.implicit_outputs.push_back(paths::FogFile(file).generic_string());
      f.rule = "fog_fit";
      f.inputs = r.outputs;
      f.implicit_inputs = {ctx.ToolPath(tool())};
      f.variables = {{"args", fmt::format("fit --name {} --angle {} --channels {} --params {}", a->name, angle_, channels_, params_)}};
      ctx.Build(tool(), f);
    }
    diags.ThrowIfAny();
  }

 private:
  static std::string Size(YamlMap& m, std::string_view key, const std::string& fallback) {
    std::optional<YamlNode> n = m.Get(key);
    if (!n) return fallback;
    const std::optional<std::string> text = n->ToString("WxH, e.g. 32x32");
    if (!text || !ParseSize(*text, 2, 4096)) {
      if (text) n->ErrorExpected(SizeExpected(2, 4096, "32x32"));
      return fallback;
    }
    return *text;
  }

  bool enabled_ = false;
  std::string method_ = "orders";
  Quality quality_ = Quality::kLow;
  int stride_ = 1;
  double cut_km_ = 1.0;
  std::string time_mapping_ = "gt7-quadratic";
  std::string lut_size_ = "32x32";
  std::string attenuation_size_ = "64x64";
  std::vector<double> sun_zenith_deg_ = {30, 60, 80, 88, 92, 96};
  int elevations_ = 9;
  std::vector<double> azimuths_deg_ = {0, 30, 90, 150, 180};
  int depths_ = 16;
  std::string angle_ = "path";
  std::string channels_ = "rgb";
  std::string params_ = "per-slice-elevation";
  int shards_ = 1;
  std::vector<std::pair<std::string, FileLoc>> skies_;
};

}  // namespace

std::unique_ptr<Stage> MakeFogFitStage() { return std::make_unique<FogFitStage>(); }

}  // namespace skybake
