#include "shards.h"

#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

namespace skybake {

int ShardsOr(YamlMap& map, int fallback) {
  return static_cast<int>(map.IntegerOr("shards", 1, 4096, "a whole number of shards from 1 to 4096", fallback));
}

int TimeMappingSlices(const std::string& name) {
  const size_t colon = name.find(':');
  int upper = 48, lower = 16;  // GT7's 48 + 16 slices (lut/gt7_mapping.h, TimeMappingKind)
  if (colon != std::string::npos) std::sscanf(name.c_str() + colon + 1, "%d+%d", &upper, &lower);
  return upper + lower;
}

std::string ShardOutput(const std::string& product, int k, int n) {
  const std::filesystem::path p(product);
  return (p.parent_path() / "shards" / fmt::format("{}.{}-of-{}{}", p.stem().string(), k, n, p.extension().string()))
      .generic_string();
}

NinjaRule ShardMergeRule(GenContext& ctx, const std::string& rule_name, const std::string& tool) {
  NinjaRule r = ToolRule(ctx, rule_name, tool, "");
  r.description = tool + " merge $out";
  return r;
}

void BuildSharded(GenContext& ctx, const std::string& tool, NinjaBuild render, const std::string& product_args,
                  int shards, const std::string& merge_rule) {
  std::string* args = nullptr;
  for (auto& [key, value] : render.variables) {
    if (key == "args") args = &value;
  }
  SKYBAKE_CHECK(args != nullptr && render.outputs.size() == 1);
  if (shards <= 1) {
    *args += product_args;
    ctx.Build(tool, render);
    return;
  }
  NinjaBuild merge;
  merge.outputs = render.outputs;
  merge.implicit_outputs = render.implicit_outputs;
  merge.rule = merge_rule;
  merge.implicit_inputs = {ctx.ToolPath(tool)};
  merge.variables = {{"args", "merge" + product_args}};
  const std::string render_args = *args;
  for (int k = 0; k < shards; ++k) {
    NinjaBuild shard = render;
    shard.outputs = {ShardOutput(render.outputs[0], k, shards)};
    shard.implicit_outputs.clear();
    for (auto& [key, value] : shard.variables) {
      if (key == "args") value = render_args + fmt::format(" --shard {}/{}", k, shards);
    }
    ctx.Build(tool, shard);
    merge.inputs.push_back(shard.outputs[0]);
  }
  ctx.Build(tool, merge);
}

}  // namespace skybake
