// Shards of a reference fog render (sky-render fog --shard K/N, sky-render merge; docs/cluster.md,
// docs/fog.md "Reference renders").
//
// A fog render (fog/fog_render.h) is a list of T = S + D independent tasks: the S LUT slices
// (task t < S is slice t) and then the D depth tables in the listed order of --sun-zenith-deg
// (task S + s is table s). Each task is computed alone with the bytes the whole render gives it:
// the `orders` method evaluates one view segment per call from its per-atmosphere tables (which
// every shard builds again), and the path tracer draws one stream per (product, element), keyed
// by the slice texel or the table element, never by the shard. Shard K of N renders tasks
// [floor(K T / N), floor((K+1) T / N)) (transport/sky_shard.h, ShardTasks). The small parts,
// depth_transmittance, attenuation and sun (spectral quadratures of the transmittance, no
// scattering: well under one slice's cost), belong to shard 0.
//
// A shard's file is the fog render's multi-part EXR restricted to the parts it computed (the same
// part names, attributes and provenance; the shard is not a parameter) plus a part "shard": T x 1
// texels, channel "owned" (1 where the shard computed the task), ints
// skybake.shard.{index,count,slices,tables}, string skybake.shard.render = "fog", and the
// render's provenance. MergeFogShards joins the N files into the bytes of the unsharded render.
#pragma once

#include <string>
#include <vector>

#include "fog/fog_render.h"
#include "io/exr.h"
#include "transport/sky_shard.h"

namespace skybake::fog {

// The value of skybake.shard.render in a fog shard's "shard" part.
inline constexpr const char* kFogShardRender = "fog";

// What one shard of a fog render computes: LUT slices [slice_begin, slice_end), depth tables
// [table_begin, table_end), and with small_parts the depth_transmittance, attenuation and sun.
struct FogShardRange {
  size_t slice_begin = 0, slice_end = 0;
  size_t table_begin = 0, table_end = 0;
  bool small_parts = false;
};

// The range of `shard` over `slices` LUT slices and `tables` depth tables (the whole render for 0/1).
FogShardRange FogShardRangeOf(const ShardSpec& shard, size_t slices, size_t tables);

// --shard K/N of sky-render fog for these options (their time mapping and sun zenith angles give
// the task count): UsageError for a malformed value or more shards than tasks.
ShardSpec ParseFogShard(const std::string& text, const FogRenderOptions& options);

// The "shard" part described above (provenance is the writer's).
ExrImage FogShardPart(const ShardSpec& shard, size_t slices, size_t tables);

// True when the file's parts are a fog render's shard (a "shard" part with skybake.shard.render = fog).
bool IsFogShard(const std::vector<ExrPart>& parts);

// Joins the N shard files of one fog render (any order) into the parts of the unsharded render.
// Throws InputError naming the file when a file is not a fog shard, belongs to another render
// (shard count, task counts or provenance), repeats a shard, leaves a task uncomputed or
// computes one twice, or when a shard of the N is missing.
std::vector<ExrPart> MergeFogShards(const std::vector<ShardFile>& shards);

}  // namespace skybake::fog
