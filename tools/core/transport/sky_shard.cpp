#include "transport/sky_shard.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <set>

#include <fmt/format.h>

#include "io/error.h"

namespace skybake {

namespace {

// The parts of a render that are not one slice's sky image (transport/sky_scene.h, WriteRender).
bool IsSkyPart(const std::string& name) {
  return name != "transmittance" && name != "sun" && name != "irradiance" && name != kShardPart;
}

int IntOf(const ExrImage& img, const std::string& key, const std::string& file) {
  auto it = img.ints.find(key);
  if (it == img.ints.end()) throw InputError(FileLoc{file, 0}, "shard part without attribute " + key);
  return it->second;
}

std::string StringOr(const ExrImage& img, const std::string& key) {
  auto it = img.strings.find(key);
  return it == img.strings.end() ? std::string() : it->second;
}

// One shard file, checked and indexed.
struct Shard {
  const ShardFile* file = nullptr;
  int index = 0, count = 0, slices = 0, first_slice = 0;
  std::vector<const ExrImage*> sky;  // its slices' sky parts, in slice order
  std::vector<std::string> sky_names;
  const ExrImage* owned = nullptr;  // the shard part
  std::map<std::string, const ExrImage*> tables;
};

Shard IndexShard(const ShardFile& f) {
  Shard s;
  s.file = &f;
  for (const ExrPart& p : f.parts) {
    if (p.name == kShardPart) {
      s.owned = &p.image;
    } else if (IsSkyPart(p.name)) {
      s.sky.push_back(&p.image);
      s.sky_names.push_back(p.name);
    } else {
      s.tables[p.name] = &p.image;
    }
  }
  const FileLoc loc{f.path, 0};
  if (!s.owned) throw InputError(loc, "not a shard of a render (no 'shard' part: render it with sky-render render --shard K/N)");
  for (const char* t : {"transmittance", "sun", "irradiance"}) {
    if (!s.tables.count(t)) throw InputError(loc, fmt::format("shard without its '{}' part", t));
  }
  s.index = IntOf(*s.owned, "skybake.shard.index", f.path);
  s.count = IntOf(*s.owned, "skybake.shard.count", f.path);
  s.slices = IntOf(*s.owned, "skybake.shard.slices", f.path);
  s.first_slice = IntOf(*s.owned, "skybake.shard.first_slice", f.path);
  if (s.count < 1 || s.index < 0 || s.index >= s.count || s.first_slice < 0 ||
      s.first_slice + static_cast<int>(s.sky.size()) > s.slices || s.owned->channels != std::vector<std::string>{"owned"}) {
    throw InputError(loc, "malformed shard part");
  }
  for (const ExrImage* img : s.sky) {
    if (img->width != s.owned->width || img->height * static_cast<int>(s.sky.size()) != s.owned->height) {
      throw InputError(loc, "the shard part does not match the shard's sky images");
    }
  }
  return s;
}

// What two shards of one render share: the resolved parameters and the inputs with their hashes.
std::string ProvenanceOf(const Shard& s) {
  const ExrImage& t = *s.tables.at("transmittance");
  return StringOr(t, "skybake.tool") + "\n" + StringOr(t, "skybake.parameters") + "\n" + StringOr(t, "skybake.inputs");
}

// A table whose last axis is the slice axis, joined from one row per slice: rows[si] = (shard,
// slice position in it). Every attribute beyond the table's own is the first row's shard's.
ExrImage JoinSliceTable(const std::vector<std::pair<const Shard*, size_t>>& rows, const std::string& name) {
  std::map<const Shard*, ExrTable> tables;
  for (const auto& [shard, at] : rows) {
    if (!tables.count(shard)) tables[shard] = ImageToTable(*shard->tables.at(name), shard->file->path);
  }
  const ExrTable& first = tables.at(rows.front().first);
  ExrTable out = first;
  out.axes.back().values.clear();
  out.values.clear();
  for (const auto& [shard, at] : rows) {
    const ExrTable& t = tables.at(shard);
    const size_t n = t.axes.back().values.size();
    if (t.channels != first.channels || t.Count() % n != 0 || t.Count() / n != first.Count() / first.axes.back().values.size()) {
      throw InputError(FileLoc{shard->file->path, 0}, "table '" + name + "' does not match the other shards'");
    }
    const size_t stride = t.Count() / n * t.channels.size();
    out.axes.back().values.push_back(t.axes.back().values.at(at));
    out.values.insert(out.values.end(), t.values.begin() + static_cast<std::ptrdiff_t>(at * stride),
                      t.values.begin() + static_cast<std::ptrdiff_t>((at + 1) * stride));
  }
  ExrImage img = TableToImage(out);
  const ExrImage& src = *rows.front().first->tables.at(name);
  for (const auto& [k, v] : src.strings) img.strings.emplace(k, v);
  for (const auto& [k, v] : src.doubles) img.doubles.emplace(k, v);
  for (const auto& [k, v] : src.ints) {
    if (k != "chunkCount") img.ints.emplace(k, v);  // OpenEXR's, of the shard's fewer rows
  }
  for (const auto& [k, v] : src.float_vectors) img.float_vectors.emplace(k, v);
  img.chromaticities = src.chromaticities;
  return img;
}

}  // namespace

std::optional<ShardSpec> ParseShard(const std::string& text) {
  const size_t slash = text.find('/');
  if (slash == std::string::npos) return std::nullopt;
  auto number = [](const std::string& s) -> std::optional<int> {
    int v = 0;
    if (s.empty() || s.size() > 4 || s.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    std::from_chars(s.data(), s.data() + s.size(), v);
    return v;
  };
  const std::optional<int> k = number(text.substr(0, slash)), n = number(text.substr(slash + 1));
  if (!k || !n || *n < 1 || *n > 4096 || *k >= *n) return std::nullopt;
  return ShardSpec{*k, *n};
}

std::pair<uint64_t, uint64_t> ShardTasks(const ShardSpec& shard, uint64_t total) {
  // total < 2^40 tasks (8192^2 texels x 4096 slices) and N <= 4096: the products fit in 64 bits.
  const uint64_t n = static_cast<uint64_t>(shard.count);
  return {total * static_cast<uint64_t>(shard.index) / n, total * static_cast<uint64_t>(shard.index + 1) / n};
}

ExrImage ShardPart(const ShardSpec& shard, size_t slice_count, size_t first_slice, int width, int height,
                   const std::vector<std::vector<uint8_t>>& owned) {
  ExrImage img;
  img.Resize(width, height * static_cast<int>(owned.size()), {"owned"});
  const size_t texels = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (size_t s = 0; s < owned.size(); ++s) {
    for (size_t t = 0; t < texels; ++t) img.pixels[s * texels + t] = owned[s][t] ? 1.0f : 0.0f;
  }
  img.strings["skybake.quantity"] = "texels this shard computed (1), per slice it touches (sky-render render --shard)";
  img.ints["skybake.shard.index"] = shard.index;
  img.ints["skybake.shard.count"] = shard.count;
  img.ints["skybake.shard.slices"] = static_cast<int>(slice_count);
  img.ints["skybake.shard.first_slice"] = static_cast<int>(first_slice);
  return img;
}

std::vector<ExrPart> MergeRenderShards(const std::vector<ShardFile>& files) {
  SKYBAKE_CHECK(!files.empty());
  std::vector<Shard> shards;
  for (const ShardFile& f : files) shards.push_back(IndexShard(f));
  const Shard& ref = shards.front();
  for (const Shard& s : shards) {
    const FileLoc loc{s.file->path, 0};
    if (s.count != ref.count || s.slices != ref.slices || ProvenanceOf(s) != ProvenanceOf(ref) ||
        s.owned->width != ref.owned->width) {
      throw InputError(loc, "a shard of another render than " + ref.file->path + " (its shard count, slices or provenance differ)");
    }
  }
  const std::map<int, const Shard*> by_index = ShardsByIndex(shards, "render");
  // Every texel of every slice is computed by exactly one shard; texel 0's shard holds the slice's
  // ambient and table rows and its part is the base of the merged slice.
  const size_t W = static_cast<size_t>(ref.owned->width);
  std::vector<ExrPart> merged;
  std::vector<std::pair<const Shard*, size_t>> rows;
  for (int si = 0; si < ref.slices; ++si) {
    std::vector<std::pair<const Shard*, size_t>> touching;
    for (const auto& [k, s] : by_index) {
      if (si >= s->first_slice && si < s->first_slice + static_cast<int>(s->sky.size())) {
        touching.emplace_back(s, static_cast<size_t>(si - s->first_slice));
      }
    }
    if (touching.empty()) throw InputError(FileLoc{ref.file->path, 0}, fmt::format("no shard holds slice {}", si));
    const size_t texels = W * static_cast<size_t>(touching.front().first->sky[touching.front().second]->height);
    std::vector<int> owner(texels, -1);
    for (size_t i = 0; i < touching.size(); ++i) {
      const auto& [s, at] = touching[i];
      const ExrImage& img = *s->sky[at];
      if (img.width * img.height != static_cast<int>(texels) || img.channels != touching.front().first->sky[touching.front().second]->channels) {
        throw InputError(FileLoc{s->file->path, 0}, fmt::format("slice {} does not match the other shards'", si));
      }
      for (size_t t = 0; t < texels; ++t) {
        if (s->owned->pixels[at * texels + t] == 0.0f) continue;
        if (owner[t] >= 0) {
          throw InputError(FileLoc{s->file->path, 0},
                           fmt::format("slice {} texel {} is computed by two shards (also {})", si, t,
                                       touching[static_cast<size_t>(owner[t])].first->file->path));
        }
        owner[t] = static_cast<int>(i);
      }
    }
    for (size_t t = 0; t < texels; ++t) {
      if (owner[t] < 0) throw InputError(FileLoc{ref.file->path, 0}, fmt::format("slice {} texel {} is in no shard", si, t));
    }
    const auto& [base_shard, base_at] = touching[static_cast<size_t>(owner[0])];
    ExrPart part{base_shard->sky_names[base_at], *base_shard->sky[base_at]};
    const size_t nc = part.image.channels.size();
    for (size_t t = 0; t < texels; ++t) {
      const auto& [s, at] = touching[static_cast<size_t>(owner[t])];
      std::copy_n(s->sky[at]->pixels.begin() + static_cast<std::ptrdiff_t>(t * nc), nc,
                  part.image.pixels.begin() + static_cast<std::ptrdiff_t>(t * nc));
    }
    merged.push_back(std::move(part));
    rows.emplace_back(base_shard, base_at);
  }
  merged.push_back({"transmittance", *rows.front().first->tables.at("transmittance")});
  merged.push_back({"sun", JoinSliceTable(rows, "sun")});
  merged.push_back({"irradiance", JoinSliceTable(rows, "irradiance")});
  return merged;
}

}  // namespace skybake
