// Shards of a sky render (sky-render render --shard K/N, sky-render merge; docs/cluster.md).
//
// A render is a list of independent tasks, each computed alone from the scene with the bytes the
// whole render gives it:
//   path (the Monte-Carlo reference)   one task per (slice, mirror-pair texel), slice-major: the
//                                      texel's random stream is keyed by (slice, texel) and its
//                                      adaptive stop is the texel's own (PathTracer::Radiance),
//                                      so no quantity couples texels;
//   deterministic methods (orders ...) one task per slice: a slice's texels share the method's
//                                      per-slice work, and the per-atmosphere precompute (the
//                                      tables) is repeated by every shard.
// Shard K of N renders tasks [floor(K T / N), floor((K+1) T / N)) of the T tasks. Its file is the
// render's multi-part EXR restricted to the slices it touches (the sky parts of those slices with
// the whole render's names and provenance; the sun and irradiance tables with their rows), plus a
// part "shard" that says which texels it computed. A slice's ambient irradiance (one path-traced
// or integrated value per slice) belongs to the shard holding the slice's texel 0.
// MergeRenderShards joins the N files into the bytes of the unsharded render.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/error.h"
#include "io/exr.h"

namespace skybake {

inline constexpr const char* kShardPart = "shard";

struct ShardSpec {
  int index = 0;
  int count = 1;
};

// "K/N" with 0 <= K < N <= 4096, digits only; nullopt otherwise.
std::optional<ShardSpec> ParseShard(const std::string& text);

// The task range [begin, end) of shard `shard` over `total` tasks: floor(K total / N) ..
// floor((K+1) total / N).
std::pair<uint64_t, uint64_t> ShardTasks(const ShardSpec& shard, uint64_t total);

// The "shard" part of a shard's file: width x (height * slices) texels, channel "owned" (1 where
// the shard computed the texel), ints skybake.shard.{index,count,slices,first_slice}.
ExrImage ShardPart(const ShardSpec& shard, size_t slice_count, size_t first_slice, int width, int height,
                   const std::vector<std::vector<uint8_t>>& owned);

struct ShardFile {
  std::string path;  // for messages
  std::vector<ExrPart> parts;
};

// The merge's inputs by shard index, each of 0 .. count - 1 exactly once. S is a merge's view of
// one input: its `index`, `count` and `file` (a ShardFile*); the counts are already known to
// agree. InputError at the file of a repeated index ("shard k/N is given twice (also F)") or, at
// the first file, for a missing one ("shard k/N of this <what> is missing from the merge's inputs").
template <typename S>
std::map<int, const S*> ShardsByIndex(const std::vector<S>& shards, const std::string& what) {
  std::map<int, const S*> by_index;
  for (const S& s : shards) {
    if (!by_index.emplace(s.index, &s).second) {
      throw InputError(FileLoc{s.file->path, 0},
                       fmt::format("shard {}/{} is given twice (also {})", s.index, s.count, by_index[s.index]->file->path));
    }
  }
  const S& first = shards.front();
  for (int k = 0; k < first.count; ++k) {
    if (!by_index.count(k)) {
      throw InputError(FileLoc{first.file->path, 0},
                       fmt::format("shard {}/{} of this {} is missing from the merge's inputs", k, first.count, what));
    }
  }
  return by_index;
}

// Joins the N shard files of one render (any order) into the parts of the unsharded render.
// Throws InputError naming the file when a file is not a shard, belongs to another render
// (provenance), repeats a shard, or when a shard of the N is missing.
std::vector<ExrPart> MergeRenderShards(const std::vector<ShardFile>& shards);

}  // namespace skybake
