// Sharded render edges (docs/cluster.md): one sky-render render edge split into N shard edges
// (`--shard k/N`, each writing outputs/<atm>/shards/<product>.<k>-of-<N>.exr) and a merge edge
// (`sky-render merge`) that writes the product from them with the bytes of the unsharded render.
// Ninja runs the shards in parallel (through the stage's pool and the tool's launcher) and, as
// each shard is its own edge with restat, re-runs only the shards whose inputs changed or whose
// file is missing.
#pragma once

#include <string>

#include "io/yaml.h"
#include "stage.h"

namespace skybake {

// `shards: N` of a stage's section or of one sky (1 to 4096 shards); `fallback` when absent.
int ShardsOr(YamlMap& map, int fallback);

// The slice count of a valid GT7 time mapping name (gt7 or gt7-quadratic, optionally
// ":<upper>+<lower>"): a deterministic render has one shard task per slice.
int TimeMappingSlices(const std::string& name);

// The file of shard k of n of a product `<atm>/<name>.exr`: `<atm>/shards/<name>.<k>-of-<n>.exr`.
std::string ShardOutput(const std::string& product, int k, int n);

// The merge rule of a stage: `<launcher>sky-render --quiet merge $args --depfile $out.d -o $out $in`
// (restat, depfile), no pool (a merge copies texels).
NinjaRule ShardMergeRule(GenContext& ctx, const std::string& rule_name, const std::string& tool);

// Emits `render` (outputs[0] the product, variable "args" its render arguments) as it is when
// shards <= 1, with `product_args` appended to its args; else as `shards` shard edges and one
// merge edge (rule `merge_rule`) that owns the product, render's implicit outputs and
// `product_args` (the options that write the product's companions, e.g. ` --preview sky.png`).
void BuildSharded(GenContext& ctx, const std::string& tool, NinjaBuild render, const std::string& product_args,
                  int shards, const std::string& merge_rule);

}  // namespace skybake
