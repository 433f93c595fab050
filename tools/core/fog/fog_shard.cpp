#include "fog/fog_shard.h"

#include <algorithm>
#include <iterator>
#include <map>

#include <fmt/format.h>

#include "io/error.h"
#include "io/exr_attributes.h"
#include "lut/gt7_mapping.h"

namespace skybake::fog {

namespace {

// The parts of a fog render that are not a task (fog/fog_render.h): shard 0's.
constexpr const char* kSmallParts[] = {"depth_transmittance", "attenuation", "sun"};

bool IsSmallPart(const std::string& name) {
  for (const char* p : kSmallParts) {
    if (name == p) return true;
  }
  return false;
}

// The render's origin as every part of it records it (io/exr.h, SetProvenance).
std::string ProvenanceOf(const ExrImage& img) {
  std::string out;
  for (const char* key : {"skybake.tool", "skybake.version", "skybake.parameters", "skybake.inputs"}) {
    const std::string* v = FindStringAttribute(img, key);
    out += std::string(key) + "=" + (v ? *v : std::string("(none)")) + "\n";
  }
  return out;
}

int IntOf(const ExrImage& img, const std::string& key, const std::string& file) {
  auto it = img.ints.find(key);
  if (it == img.ints.end()) throw InputError(FileLoc{file, 0}, "shard part without attribute " + key);
  return it->second;
}

// One fog shard file, checked and indexed.
struct Shard {
  const ShardFile* file = nullptr;
  int index = 0, count = 0, slices = 0, tables = 0;
  std::string provenance;
  std::vector<std::pair<size_t, const ExrPart*>> tasks;  // (task, its part), ascending
  std::map<std::string, const ExrPart*> small;
};

Shard IndexShard(const ShardFile& f) {
  const FileLoc loc{f.path, 0};
  Shard s;
  s.file = &f;
  const ExrImage* owned = nullptr;
  for (const ExrPart& p : f.parts) {
    if (p.name == kShardPart) owned = &p.image;
  }
  const std::string* render = owned ? FindStringAttribute(*owned, "skybake.shard.render") : nullptr;
  if (!render || *render != kFogShardRender) {
    throw InputError(loc, "not a shard of a fog render (render it with sky-render fog --shard K/N)");
  }
  s.index = IntOf(*owned, "skybake.shard.index", f.path);
  s.count = IntOf(*owned, "skybake.shard.count", f.path);
  s.slices = IntOf(*owned, "skybake.shard.slices", f.path);
  s.tables = IntOf(*owned, "skybake.shard.tables", f.path);
  s.provenance = ProvenanceOf(*owned);
  if (s.count < 1 || s.index < 0 || s.index >= s.count || s.slices < 1 || s.tables < 1 ||
      owned->width != s.slices + s.tables || owned->height != 1 || owned->channels != std::vector<std::string>{"owned"}) {
    throw InputError(loc, "malformed shard part");
  }
  std::vector<size_t> computed;
  for (size_t t = 0; t < owned->pixels.size(); ++t) {
    if (owned->pixels[t] != 0.0f) computed.push_back(t);
  }
  // The task parts follow the render's order (slices, then tables), one per computed task.
  size_t next = 0;
  for (const ExrPart& p : f.parts) {
    if (p.name == kShardPart) continue;
    if (ProvenanceOf(p.image) != s.provenance) {
      throw InputError(loc, "part '" + p.name + "' records another origin (provenance) than the file's shard part");
    }
    if (IsSmallPart(p.name)) {
      s.small[p.name] = &p;
      continue;
    }
    if (next >= computed.size()) throw InputError(loc, "part '" + p.name + "' is not a task the shard part marks");
    const size_t task = computed[next++];
    const bool slice = task < static_cast<size_t>(s.slices);
    const bool matches = slice ? NumberedPartIndex(p.name, "fog.slice_") == static_cast<int>(task)
                               : p.name.rfind("depth.", 0) == 0;
    if (!matches) {
      throw InputError(loc, fmt::format("part '{}' is not task {} the shard part marks ({})", p.name, task,
                                        slice ? fmt::format("LUT slice {}", task)
                                              : fmt::format("depth table {}", task - static_cast<size_t>(s.slices))));
    }
    s.tasks.emplace_back(task, &p);
  }
  if (next != computed.size()) throw InputError(loc, fmt::format("the shard part marks {} tasks, the file holds {}", computed.size(), next));
  if (!s.small.empty() && s.small.size() != std::size(kSmallParts)) {
    throw InputError(loc, "a shard holds all of depth_transmittance, attenuation and sun or none of them");
  }
  return s;
}

}  // namespace

FogShardRange FogShardRangeOf(const ShardSpec& shard, size_t slices, size_t tables) {
  const auto [begin, end] = ShardTasks(shard, slices + tables);
  FogShardRange r;
  r.slice_begin = std::min<size_t>(begin, slices);
  r.slice_end = std::min<size_t>(end, slices);
  r.table_begin = std::max<size_t>(begin, slices) - slices;
  r.table_end = std::max<size_t>(end, slices) - slices;
  r.small_parts = shard.index == 0;
  return r;
}

ShardSpec ParseFogShard(const std::string& text, const FogRenderOptions& o) {
  const std::optional<ShardSpec> shard = ParseShard(text);
  if (!shard) throw UsageError("--shard: expected K/N with 0 <= K < N <= 4096 (e.g. 0/4), got '" + text + "'");
  // An unknown time mapping is refused by RenderFog, before any work, with the accepted names.
  if (const std::optional<gt7::TimeMappingKind> kind = gt7::TimeMapping::ParseName(o.time_mapping)) {
    const size_t slices = static_cast<size_t>(kind->upper + kind->lower), tables = o.sun_zenith_deg.size();
    if (static_cast<size_t>(shard->count) > slices + tables) {
      throw UsageError(fmt::format("--shard {}: this fog render has {} LUT slices and {} depth tables ({} tasks), fewer "
                                   "than {} shards",
                                   text, slices, tables, slices + tables, shard->count));
    }
  }
  return *shard;
}

ExrImage FogShardPart(const ShardSpec& shard, size_t slices, size_t tables) {
  ExrImage img;
  img.Resize(static_cast<int>(slices + tables), 1, {"owned"});
  const FogShardRange r = FogShardRangeOf(shard, slices, tables);
  for (size_t t = r.slice_begin; t < r.slice_end; ++t) img.pixels[t] = 1.0f;
  for (size_t t = r.table_begin; t < r.table_end; ++t) img.pixels[slices + t] = 1.0f;
  img.strings["skybake.quantity"] =
      "tasks this shard computed (1): the LUT slices, then the depth tables in the order of --sun-zenith-deg "
      "(sky-render fog --shard)";
  img.strings["skybake.shard.render"] = kFogShardRender;
  img.ints["skybake.shard.index"] = shard.index;
  img.ints["skybake.shard.count"] = shard.count;
  img.ints["skybake.shard.slices"] = static_cast<int>(slices);
  img.ints["skybake.shard.tables"] = static_cast<int>(tables);
  return img;
}

bool IsFogShard(const std::vector<ExrPart>& parts) {
  for (const ExrPart& p : parts) {
    if (p.name != kShardPart) continue;
    const std::string* render = FindStringAttribute(p.image, "skybake.shard.render");
    return render && *render == kFogShardRender;
  }
  return false;
}

std::vector<ExrPart> MergeFogShards(const std::vector<ShardFile>& files) {
  SKYBAKE_CHECK(!files.empty());
  std::vector<Shard> shards;
  for (const ShardFile& f : files) shards.push_back(IndexShard(f));
  const Shard& ref = shards.front();
  for (const Shard& s : shards) {
    const FileLoc loc{s.file->path, 0};
    if (s.count != ref.count || s.slices != ref.slices || s.tables != ref.tables || s.provenance != ref.provenance) {
      throw InputError(loc, "a shard of another fog render than " + ref.file->path +
                                " (its shard count, task counts or provenance differ)");
    }
  }
  const std::map<int, const Shard*> by_index = ShardsByIndex(shards, "fog render");
  const size_t total = static_cast<size_t>(ref.slices + ref.tables);
  std::vector<std::pair<const Shard*, const ExrPart*>> slots(total, {nullptr, nullptr});
  const Shard* small = nullptr;
  for (const auto& [k, s] : by_index) {
    for (const auto& [task, part] : s->tasks) {
      if (slots[task].first) {
        throw InputError(FileLoc{s->file->path, 0},
                         fmt::format("task {} ({}) is computed by two shards (also {})", task, part->name,
                                     slots[task].first->file->path));
      }
      slots[task] = {s, part};
    }
    if (!s->small.empty()) {
      if (small) {
        throw InputError(FileLoc{s->file->path, 0},
                         "depth_transmittance, attenuation and sun are in two shards (also " + small->file->path + ")");
      }
      small = s;
    }
  }
  for (size_t t = 0; t < total; ++t) {
    if (!slots[t].first) {
      throw InputError(FileLoc{ref.file->path, 0},
                       t < static_cast<size_t>(ref.slices)
                           ? fmt::format("LUT slice {} is in no shard", t)
                           : fmt::format("depth table {} is in no shard", t - static_cast<size_t>(ref.slices)));
    }
  }
  if (!small) throw InputError(FileLoc{ref.file->path, 0}, "no shard holds depth_transmittance, attenuation and sun");
  std::vector<ExrPart> merged;
  for (const auto& [s, part] : slots) merged.push_back(*part);
  for (const char* name : kSmallParts) merged.push_back(*small->small.at(name));
  return merged;
}

}  // namespace skybake::fog
