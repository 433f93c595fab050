// lut-pack edges: GT7 sky LUTs of the basis skies (docs/lut-pack.md, docs/pipeline.md).
//
//   outputs/<atm>/lut_sky.exr         sky-render render on the GT7 mappings (one per basis sky)
//   outputs/luts/report.json          lut-pack pack of the whole set, with beside it
//   outputs/luts/sky_<atm>.ktx2 ...   the textures (lut-pack's output list, paths.h)
//
// Only with a `luts` section in pipeline.yaml:
//   luts:
//     method: orders               # sky-render method of the LUT renders (docs/sky-methods.md)
//     quality: medium              # its quality preset (a sky may name its own: below)
//     spectral_stride: 2           # the method on every 2nd wavelength, transfer interpolated (1 = all;
//                                  # a sky may name its own)
//     time_mapping: gt7-quadratic  # or gt7 (the talk's; docs/lut-pack.md), optionally ":<upper>+<lower>"
//     sky_exposure_stops: auto     # or N: sky texels store cd/m^2 x 2^N (auto: per texture, no clamping)
//     budget_mib: 3.5              # lut-pack fails when the sky LUTs exceed it
//     skies:                       # the basis skies of the set, in row order of the other LUTs
//       - {atmosphere: clear, size: 32x128}
//       - {atmosphere: cloudy0, size: 16x64}
//       - {atmosphere: hazed, size: 32x128, quality: high}  # this sky's quality instead of the section's
//       - {atmosphere: cloudy2, size: 16x64, quality: auto, tolerance: 0.5%}  # chosen by sky-render choose
//     shards: 4                    # each render as 4 shard edges + a merge (a sky may name its own;
//                                  # docs/cluster.md), at most one per slice of the time mapping
// `quality: auto` (the section's or a sky's; docs/sky-methods.md "Automatic quality"): a
// `sky-render choose` edge writes outputs/<atm>/lut_quality.yaml, the cheapest quality and
// spectral stride whose sky is within `tolerance` (daylight RMS, default 0.5 %), `max_tolerance`
// (daylight max, 2 %) and `twilight_tolerance` (twilight RMS, 3 %) of the method's full model, and
// the render edge reads it (--settings) instead of the section's quality and stride.
// Each render edge depends on its atmosphere's render component (written by the sky-render
// stage), profiles and Mie tables, so an edit to one atmosphere re-renders only its LUT (and
// re-chooses its quality) and re-runs the pack edge, whose unchanged textures keep their bytes and
// times (write-if-changed + restat; a choice whose file is unchanged re-renders nothing).
#include <cmath>
#include <fmt/format.h>

#include <set>

#include "atmosphere/spec.h"
#include "paths.h"
#include "shards.h"
#include "stage.h"
#include "stage_helpers.h"
#include "io/size.h"
#include "io/text_list.h"
#include "transport/budget.h"
#include "transport/quality.h"
#include "transport/sky_method.h"

namespace skybake {

namespace {

// `quality: auto` and its tolerances (relative), of the section or one sky.
struct AutoQuality {
  bool enabled = false;
  std::string tolerance = "0.005", max_tolerance = "0.02", twilight_tolerance = "0.03";
};

struct LutSky {
  std::string atmosphere;
  std::string size;
  Quality quality = Quality::kMedium;  // the section's unless the sky names its own
  int spectral_stride = 1;             // the section's unless the sky names its own
  int shards = 1;                      // the section's unless the sky names its own
  FileLoc loc;
  AutoQuality auto_quality;            // the section's unless the sky names its own
};

// The key `spectral_stride` of `map` (a whole number 1-64), `fallback` when absent.
int SpectralStrideOr(YamlMap& map, int fallback) {
  const double stride = map.NumberOr("spectral_stride", NumberSpec::Range(1, 64, "wavelengths"), fallback);
  if (stride != std::floor(stride)) {
    map.Get("spectral_stride")->ErrorExpected("a whole number of wavelengths from 1 to 64");
    return fallback;
  }
  return static_cast<int>(stride);
}

// Reads `quality` (low, medium, high or auto) and the tolerance keys of `map` over what the
// section (or the defaults) gave.
// A tolerance without `quality: auto` (here or inherited) is an error at its line.
void ReadQuality(YamlMap& map, Quality* quality, AutoQuality* aq) {
  if (map.Has("quality")) {
    std::vector<std::string> names = QualityNames();
    names.push_back("auto");
    const std::string q = map.Choice("quality", names);
    if (q == "auto") {
      aq->enabled = true;
    } else if (const std::optional<Quality> fixed = FindQuality(q)) {
      *quality = *fixed;
      aq->enabled = false;
    }
  }
  for (auto [key, value] : {std::pair{"tolerance", &aq->tolerance}, std::pair{"max_tolerance", &aq->max_tolerance},
                            std::pair{"twilight_tolerance", &aq->twilight_tolerance}}) {
    std::optional<YamlNode> n = map.Get(key);
    if (!n) continue;
    const std::string expected = "a positive relative error, a percentage (0.5%) or a fraction (0.005)";
    const std::optional<std::string> text = n->ToString(expected);
    if (!text) continue;
    try {
      *value = FormatExact(ParseTolerance(*text, key));
    } catch (const UsageError&) {
      n->ErrorExpected(expected);
      continue;
    }
    if (!aq->enabled) n->Error("applies to quality: auto only (docs/sky-methods.md \"Automatic quality\")");
  }
}

class LutPackStage : public Stage {
 public:
  std::string tool() const override { return "lut-pack"; }

  void ParseConfig(YamlMap& root) override {
    std::optional<YamlMap> luts = root.OptionalMap("luts");
    if (!luts) return;
    enabled_ = true;
    method_ = luts->ChoiceOr("method", SkyMethodNames(), method_);
    ReadQuality(*luts, &quality_, &auto_);
    spectral_stride_ = SpectralStrideOr(*luts, spectral_stride_);
    time_mapping_ = TimeMappingOr(*luts, time_mapping_);
    if (std::optional<YamlNode> e = luts->Get("sky_exposure_stops")) {
      const std::optional<std::string> text = e->ToString("auto or a whole number of stops from -24 to 24");
      int stops = 0;
      char tail = 0;
      if (text && *text != "auto" &&
          (std::sscanf(text->c_str(), "%d%c", &stops, &tail) != 1 || stops < -24 || stops > 24 || *text != std::to_string(stops))) {
        e->ErrorExpected("auto or a whole number of stops from -24 to 24");
      } else if (text) {
        exposure_stops_ = *text;
      }
    }
    budget_mib_ = luts->NumberOr("budget_mib", NumberSpec::Positive("MiB"), budget_mib_);
    shards_ = ShardsOr(*luts, shards_);
    std::set<std::string> seen;
    for (const YamlNode& n : luts->Seq("skies")) {
      YamlMap m = n.ToMap("a mapping {atmosphere: NAME, size: WxH[, quality: " + TextList(QualityNames(), "|", "|") +
                          "|auto][, spectral_stride: K]}");
      if (!m.valid()) continue;
      LutSky s;
      s.loc = n.loc();
      s.atmosphere = m.String("atmosphere", "the name of an atmosphere of the list above");
      const std::string size = m.String("size", "WxH, e.g. 32x128");
      if (!size.empty() && !ParseSize(size, 2, 4096)) m.Get("size")->ErrorExpected(SizeExpected(2, 4096, "32x128"));
      s.size = size;
      s.quality = quality_;
      s.auto_quality = auto_;
      ReadQuality(m, &s.quality, &s.auto_quality);
      s.spectral_stride = SpectralStrideOr(m, spectral_stride_);
      if (s.auto_quality.enabled && m.Has("spectral_stride")) {
        m.Get("spectral_stride")->Error("not with quality: auto (the choice sets the stride)");
      }
      s.shards = ShardsOr(m, shards_);
      if (s.shards > TimeMappingSlices(time_mapping_)) {
        (m.Has("shards") ? *m.Get("shards") : n)
            .Error(fmt::format("{} shards for the {} slices of time mapping {}: at most one shard per slice",
                               s.shards, TimeMappingSlices(time_mapping_), time_mapping_));
      }
      m.Finish();
      if (!s.atmosphere.empty() && !seen.insert(s.atmosphere).second) n.Error("basis sky '" + s.atmosphere + "' is listed twice");
      skies_.push_back(s);
    }
    if (skies_.empty()) luts->node().Error("luts.skies: expected at least one basis sky");
    luts->Finish();
  }

  void EmitRules(GenContext& ctx) const override {
    if (!enabled_) return;
    const std::string pool = ctx.pipeline().pools.count("render") ? "render" : "";
    ctx.ninja().Rule(ToolRule(ctx, "lut_render", "sky-render", pool));
    bool any_auto = false;
    for (const LutSky& s : skies_) any_auto = any_auto || s.auto_quality.enabled;
    if (any_auto) ctx.ninja().Rule(ToolRule(ctx, "lut_choose", "sky-render", pool));
    bool sharded = false;
    for (const LutSky& s : skies_) sharded = sharded || s.shards > 1;
    if (sharded) ctx.ninja().Rule(ShardMergeRule(ctx, "lut_merge", "sky-render"));
    NinjaRule r;
    r.name = "lut_pack";
    r.command = ctx.LauncherPrefix(tool()) + ctx.ToolPath(tool()) + " --quiet pack $skies $args --depfile $out.d -o $out";
    r.description = tool() + " $out";
    r.depfile = "$out.d";
    r.deps = "gcc";
    r.restat = true;
    ctx.ninja().Rule(r);
  }

  void EmitEdges(GenContext& ctx) const override {
    if (!enabled_) return;
    const auto& wl = ctx.pipeline().wavelengths;
    Diagnostics diags;
    std::vector<std::pair<std::string, std::string>> packed;  // name, render path
    for (const LutSky& s : skies_) {
      const PipelineAtmosphere* a = FindAtmosphere(ctx.pipeline(), s.atmosphere, "luts.skies", s.loc, &diags);
      if (!a) continue;
      const std::string scene = fmt::format("--profiles {} --mie-dir mie --wavelengths {}:{}:{}",
                                            paths::Profiles(a->name).generic_string(), FormatExact(wl.min_nm),
                                            FormatExact(wl.max_nm), FormatExact(wl.step_nm));
      NinjaBuild b;
      b.outputs = {paths::LutRender(a->name).generic_string()};
      b.rule = "lut_render";
      b.inputs = {paths::RenderComponent(a->name).generic_string()};
      b.implicit_inputs = {ctx.ToolPath("sky-render"), paths::Profiles(a->name).generic_string()};
      for (const std::string& mie : MieTableInputs(a->spec)) b.implicit_inputs.push_back(mie);
      std::string args;
      if (s.auto_quality.enabled) {
        NinjaBuild c;
        c.outputs = {paths::LutQuality(a->name).generic_string()};
        c.rule = "lut_choose";
        c.inputs = b.inputs;
        c.implicit_inputs = b.implicit_inputs;
        c.variables = {{"args", fmt::format("choose --method {} {} --tolerance {} --max-tolerance {} --twilight-tolerance {}",
                                            method_, scene, s.auto_quality.tolerance, s.auto_quality.max_tolerance,
                                            s.auto_quality.twilight_tolerance)}};
        ctx.Build("sky-render", c);
        b.implicit_inputs.push_back(c.outputs[0]);
        args = fmt::format("render --settings {} {}", c.outputs[0], scene);
      } else {
        args = fmt::format("render --method {} --quality {} {}", method_, QualityName(s.quality), scene);
        if (s.spectral_stride > 1) args += fmt::format(" --spectral-stride {}", s.spectral_stride);
      }
      args += fmt::format(" --mapping gt7 --size {} --time-mapping {}", s.size, time_mapping_);
      b.variables = {{"args", args}};
      BuildSharded(ctx, "sky-render", b, "", s.shards, "lut_merge");
      packed.emplace_back(a->name, b.outputs[0]);
    }
    diags.ThrowIfAny();

    NinjaBuild b;
    b.outputs = {paths::LutReport().generic_string()};
    std::string skies;
    for (const auto& [name, render] : packed) {
      b.inputs.push_back(render);
      skies += (skies.empty() ? "" : " ") + name + "=" + render;
      for (const std::string& f : paths::LutSkyFiles(name)) b.implicit_outputs.push_back(paths::LutFile(f).generic_string());
    }
    for (const std::string& f : paths::LutSetFiles()) b.implicit_outputs.push_back(paths::LutFile(f).generic_string());
    b.rule = "lut_pack";
    b.implicit_inputs = {ctx.ToolPath(tool())};
    b.variables = {{"skies", skies},
                   {"args", fmt::format("--sky-exposure-stops {} --budget-mib {}", exposure_stops_,
                                        FormatExact(budget_mib_))}};
    ctx.Build(tool(), b);
  }

 private:
  bool enabled_ = false;
  std::string method_ = "orders";
  Quality quality_ = Quality::kMedium;
  AutoQuality auto_;
  int spectral_stride_ = 1;
  std::string time_mapping_ = "gt7-quadratic";
  std::string exposure_stops_ = "auto";
  double budget_mib_ = 3.5;
  int shards_ = 1;
  std::vector<LutSky> skies_;
};

}  // namespace

std::unique_ptr<Stage> MakeLutPackStage() { return std::make_unique<LutPackStage>(); }

}  // namespace skybake
