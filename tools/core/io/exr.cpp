#include "io/exr.h"

#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <Iex.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <map>

#include <fmt/format.h>

#include "io/error.h"
#include "io/fileio.h"
#include "io/repo_paths.h"
#include "io/yaml.h"
#include "skybake/version.h"

namespace skybake {

// ---------------------------------------------------------------------------- in-memory streams

namespace {

class MemOStream : public Imf::OStream {
 public:
  MemOStream() : Imf::OStream("<memory>") {}
  void write(const char c[], int n) override {
    size_t end = pos_ + static_cast<size_t>(n);
    if (end > data_.size()) data_.resize(end);
    std::memcpy(data_.data() + pos_, c, static_cast<size_t>(n));
    pos_ = end;
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = pos; }
  std::string& data() { return data_; }

 private:
  std::string data_;
  size_t pos_ = 0;
};

class MemIStream : public Imf::IStream {
 public:
  MemIStream(const std::string& data, const std::string& name) : Imf::IStream(name.c_str()), data_(data) {}
  bool read(char c[], int n) override {
    // OpenEXR passes sizes it read from the file: a negative one, or one past the end (also
    // after a seek beyond it), is a corrupt file.
    if (n < 0 || pos_ > data_.size() || static_cast<size_t>(n) > data_.size() - pos_) {
      throw Iex::InputExc("Unexpected end of file.");
    }
    std::memcpy(c, data_.data() + pos_, static_cast<size_t>(n));
    pos_ += static_cast<size_t>(n);
    return pos_ < data_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }
  void clear() override {}

 private:
  const std::string& data_;
  size_t pos_ = 0;
};

}  // namespace

// ---------------------------------------------------------------------------- image helpers

void ExrImage::Resize(int w, int h, std::vector<std::string> channel_names) {
  width = w;
  height = h;
  channels = std::move(channel_names);
  pixels.assign(static_cast<size_t>(w) * h * channels.size(), 0.0f);
}

int ExrImage::ChannelIndex(const std::string& name) const {
  for (size_t i = 0; i < channels.size(); ++i) {
    if (channels[i] == name) return static_cast<int>(i);
  }
  return -1;
}

size_t ExrTable::Count() const {
  size_t n = 1;
  for (const ExrAxis& a : axes) n *= a.values.size();
  return n;
}

int ExrTable::ChannelIndex(const std::string& name) const {
  for (size_t i = 0; i < channels.size(); ++i) {
    if (channels[i] == name) return static_cast<int>(i);
  }
  return -1;
}

void Provenance::AddInput(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  // A file of the repository named by an absolute path (the CMF table or OCIO config a tool
  // found by itself, FindRepoFile) is recorded relative to the working directory, like the inputs
  // given relative: the same inputs baked in another checkout then give the same bytes
  // (docs/design.md, "File conventions"). Any other path is recorded as given.
  fs::path recorded = path;
  if (path.is_absolute()) {
    std::error_code ec;
    const fs::path cwd = fs::current_path(ec);  // symbolic links resolved, as RepoRoot's
    const fs::path canonical = ec ? fs::path() : fs::weakly_canonical(path, ec);
    const std::optional<fs::path> root = ec ? std::nullopt : RepoRoot();
    if (root) {
      const fs::path inside = canonical.lexically_relative(*root);
      const bool in_repo = !inside.empty() && *inside.begin() != "..";
      const fs::path rel = canonical.lexically_proximate(cwd);
      if (in_repo && !rel.empty() && rel.is_relative()) recorded = rel;
    }
  }
  inputs.emplace_back(recorded.lexically_normal().generic_string(), HashFile(path));
}

void SetProvenance(ExrImage& image, const Provenance& p) {
  image.strings["skybake.tool"] = p.tool;
  image.strings["skybake.version"] = kVersion;
  image.strings["skybake.parameters"] = p.parameters;
  std::string inputs;
  for (const auto& [path, hash] : p.inputs) inputs += path + " xxh3:" + hash + "\n";
  image.strings["skybake.inputs"] = inputs;
}

Imf::Chromaticities XyzChromaticities() {
  return Imf::Chromaticities(Imath::V2f(1.0f, 0.0f), Imath::V2f(0.0f, 1.0f), Imath::V2f(0.0f, 0.0f),
                             Imath::V2f(1.0f / 3.0f, 1.0f / 3.0f));
}

// ---------------------------------------------------------------------------- tables

ExrImage TableToImage(const ExrTable& t) {
  SKYBAKE_CHECK(!t.axes.empty() && t.axes.size() <= 3);
  SKYBAKE_CHECK_EQ(t.channels.size(), t.channel_units.size());
  SKYBAKE_CHECK_EQ(t.values.size(), t.Count() * t.channels.size());
  ExrImage img;
  int n0 = static_cast<int>(t.axes[0].values.size());
  int rest = static_cast<int>(t.Count() / t.axes[0].values.size());
  img.width = n0;
  img.height = rest;
  img.channels = t.channels;
  img.pixels = t.values;
  img.strings["skybake.layout"] = "table";
  img.ints["skybake.axes"] = static_cast<int>(t.axes.size());
  for (size_t k = 0; k < t.axes.size(); ++k) {
    const ExrAxis& a = t.axes[k];
    const std::string pre = fmt::format("skybake.axis{}.", k);
    img.strings[pre + "name"] = a.name;
    img.strings[pre + "unit"] = a.unit;
    img.strings[pre + "description"] = a.description;
    img.ints[pre + "size"] = static_cast<int>(a.values.size());
    // Exact coordinates as text (doubles, round-trip exact) and as floats for viewers.
    std::string exact;
    std::vector<float> f;
    for (double v : a.values) {
      if (!exact.empty()) exact += " ";
      exact += FormatExact(v);
      f.push_back(static_cast<float>(v));
    }
    img.strings[pre + "values"] = exact;
    img.float_vectors[pre + "coordinates"] = f;
  }
  for (size_t c = 0; c < t.channels.size(); ++c) {
    img.strings["skybake.unit." + t.channels[c]] = t.channel_units[c];
  }
  return img;
}

ExrTable ImageToTable(const ExrImage& img, const std::string& name) {
  auto fail = [&](const std::string& what) { throw InputError(FileLoc{name, 0}, what); };
  auto layout = img.strings.find("skybake.layout");
  if (layout == img.strings.end() || layout->second != "table") fail("not a skybake table (no skybake.layout = table)");
  auto axes = img.ints.find("skybake.axes");
  if (axes == img.ints.end() || axes->second < 1 || axes->second > 3) fail("bad skybake.axes attribute");
  ExrTable t;
  size_t count = 1;
  for (int k = 0; k < axes->second; ++k) {
    const std::string pre = fmt::format("skybake.axis{}.", k);
    ExrAxis a;
    auto get = [&](const std::string& key) -> std::string {
      auto it = img.strings.find(pre + key);
      if (it == img.strings.end()) fail("missing attribute " + pre + key);
      return it->second;
    };
    a.name = get("name");
    a.unit = get("unit");
    a.description = get("description");
    std::string vals = get("values");
    size_t pos = 0;
    while (pos < vals.size()) {
      size_t end = vals.find(' ', pos);
      if (end == std::string::npos) end = vals.size();
      // Each value is a whole finite number (the writer's {:.17g}); anything else is a bad file.
      const std::string tok = vals.substr(pos, end - pos);
      double v = 0.0;
      const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), v, std::chars_format::general);
      if (tok.empty() || res.ec != std::errc() || res.ptr != tok.data() + tok.size() || !std::isfinite(v)) {
        fail(fmt::format("attribute {}values: '{}' is not a finite number", pre, tok));
      }
      a.values.push_back(v);
      pos = end + 1;
    }
    count *= a.values.size();
    t.axes.push_back(std::move(a));
  }
  if (static_cast<size_t>(img.width) != t.axes[0].values.size() ||
      static_cast<size_t>(img.width) * img.height != count) {
    fail("table axes do not match the image size");
  }
  t.channels = img.channels;
  for (const std::string& c : t.channels) {
    auto it = img.strings.find("skybake.unit." + c);
    t.channel_units.push_back(it == img.strings.end() ? std::string() : it->second);
  }
  t.values = img.pixels;
  return t;
}

// ---------------------------------------------------------------------------- encode / decode

// The layout of an OpenEXR file's headers (OpenEXR "File Layout": the magic number 20000630,
// a version field with flags 0x200 single-part tiled, 0x400 long names, 0x800 deep, 0x1000
// multi-part; then each header as attributes `name\0 type\0 int32 size, size bytes`, ended by
// an empty name; a multi-part file's list of headers ends with an empty header; then every
// part's chunk offset table, 8 bytes per chunk). OpenEXR allocates an attribute's value, a
// part's offset table and its line buffers from these fields before it finds that the file
// cannot hold them: a 1 KB input could make it allocate gigabytes. This walk refuses such a
// file first, with the cost of reading the headers only.
//  - every attribute's size must be >= 0 and fit in the bytes that follow it;
//  - the parts' chunks (the `chunkCount` attribute, or the data window's scanline blocks of
//    the compression's height, or its level-0 tiles) need their 8-byte offsets in the rest of
//    the file;
//  - the data window times the channel count, at 2 bytes per value, is at most the largest
//    ratio of the part's compression times the file's bytes (MaxCompressionRatio).
namespace {

struct ExrPartLayout {
  bool has_window = false, has_tiles = false;
  int64_t w = 0, h = 0, channels = 0, chunk_count = -1;
  int compression = -1;  // none given; Imf::Compression: 0 none, 1 RLE, 2 ZIPS, 3 ZIP, 4 PIZ, 5 PXR24, 6 B44, 7 B44A, 8 DWAA, 9 DWAB
  uint32_t tile_x = 0, tile_y = 0;
};

int32_t LoadI32(const char* p) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return static_cast<int32_t>(v);
}

// Scanlines per chunk of each compression (OpenEXR "Compression methods").
int64_t LinesPerChunk(int compression) {
  switch (compression) {
    case 3: case 5: return 16;            // ZIP, PXR24
    case 4: case 6: case 7: case 8: return 32;  // PIZ, B44, B44A, DWAA
    case 9: return 256;                   // DWAB
    default: return 1;                    // NONE, RLE, ZIPS (an unknown one OpenEXR refuses)
  }
}

// OpenEXR reads a value of a fixed-size type by its type, whatever size the file declares, and
// a channel list or a preview by its own fields: a declared size that disagrees would make it
// read the following bytes as a different chain of attributes than the one checked here.
template <typename Refuse>
void CheckAttributeSize(const std::string& attr, const std::string& type, const char* v, int64_t size,
                        const Refuse& refuse) {
  static const std::map<std::string, int64_t> kFixed = {
      {"box2i", 16},  {"box2f", 16},  {"int", 4},        {"float", 4},     {"double", 8},
      {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"v2i", 8},     {"v2f", 8},     {"v2d", 16},       {"v3i", 12},      {"v3f", 12},
      {"v3d", 24},    {"m33f", 36},   {"m33d", 72},      {"m44f", 64},     {"m44d", 128},
      {"tiledesc", 9}, {"chromaticities", 32}, {"rational", 8}, {"timecode", 8}, {"keycode", 28}};
  auto bad = [&](const std::string& why) {
    refuse(fmt::format("attribute '{}' of type {} {}", attr, type, why));
  };
  if (auto it = kFixed.find(type); it != kFixed.end()) {
    if (size != it->second) bad(fmt::format("has {} bytes, not {}", size, it->second));
  } else if (type == "chlist") {
    // Channels: name\0 then 16 bytes each, ended by an empty name, all inside the value.
    int64_t c = 0;
    while (true) {
      if (c >= size) bad("has no end");
      if (v[c] == '\0') break;
      const void* z = std::memchr(v + c, '\0', static_cast<size_t>(size - c));
      if (!z) bad("has a channel name without an end");
      c = (static_cast<const char*>(z) - v) + 1 + 16;
    }
    if (c + 1 != size) bad(fmt::format("ends at byte {} of {}", c + 1, size));
  } else if (type == "preview") {
    // Width and height (uint32), then 4 bytes per pixel.
    if (size < 8) bad("has no dimensions");
    const uint64_t w = static_cast<uint32_t>(LoadI32(v)), h = static_cast<uint32_t>(LoadI32(v + 4));
    if (w * h * 4 + 8 != static_cast<uint64_t>(size)) bad(fmt::format("of {} x {} pixels has {} bytes", w, h, size));
  } else if (type == "floatvector") {
    if (size % 4 != 0) bad(fmt::format("has {} bytes, not a multiple of 4", size));
  }
}

// The largest ratio of pixel bytes to compressed bytes each compression can reach: NONE 1;
// RLE 64 (a 2-byte run of up to 128 bytes); ZIPS, ZIP 1032 (deflate's limit, RFC 1951: a
// 258-byte match in 2 bits at best, Adler's zlib FAQ); PXR24 1376 (deflate of 3 bytes per 4-byte
// float); B44, B44A 11 (a flat 4x4 block of half, 32 bytes, in 3); PIZ, DWAA, DWAB (run-length
// Huffman and deflate stages without a simple limit) 8192, the bound PrepareRead uses for all.
double MaxCompressionRatio(int compression) {
  switch (compression) {
    case 0: return 1.0;
    case 1: return 64.0;
    case 2: case 3: return 1032.0;
    case 5: return 1376.0;
    case 6: case 7: return 11.0;
    default: return 8192.0;
  }
}

void CheckExrLayout(const std::string& bytes, const std::string& name) {
  auto refuse = [&](const std::string& why) {
    throw InputError(FileLoc{name, 0}, "not a readable OpenEXR file: " + why);
  };
  const size_t n = bytes.size();
  if (n < 8 || LoadI32(bytes.data()) != 20000630) refuse("no OpenEXR magic number");
  const int32_t version = LoadI32(bytes.data() + 4);
  const bool multipart = (version & 0x1000) != 0, single_tiled = (version & 0x200) != 0;
  const size_t max_name = (version & 0x400) ? 255 : 31;
  size_t pos = 8;
  auto read_string = [&](const char* what) {
    const size_t end = bytes.find('\0', pos);
    if (end == std::string::npos || end - pos > max_name) refuse(fmt::format("the {} at byte {} has no end", what, pos));
    std::string s = bytes.substr(pos, end - pos);
    pos = end + 1;
    return s;
  };
  std::vector<ExrPartLayout> parts;
  while (true) {
    if (pos >= n) refuse("the headers end before the file's data");
    if (multipart && !parts.empty() && bytes[pos] == '\0') {  // the empty header ending the list
      ++pos;
      break;
    }
    ExrPartLayout part;
    part.has_tiles = single_tiled;
    while (true) {
      if (pos >= n) refuse("a header has no end");
      if (bytes[pos] == '\0') {
        ++pos;
        break;
      }
      const std::string attr = read_string("attribute name");
      const std::string type = read_string("attribute type");
      if (n - pos < 4) refuse(fmt::format("attribute '{}' has no size", attr));
      const int64_t size = LoadI32(bytes.data() + pos);
      pos += 4;
      if (size < 0 || static_cast<uint64_t>(size) > n - pos) {
        refuse(fmt::format("attribute '{}' claims {} bytes, {} are left", attr, size, n - pos));
      }
      const char* v = bytes.data() + pos;
      CheckAttributeSize(attr, type, v, size, refuse);
      if (attr == "dataWindow" && type == "box2i" && size == 16) {
        part.has_window = true;
        part.w = int64_t{LoadI32(v + 8)} - LoadI32(v) + 1;
        part.h = int64_t{LoadI32(v + 12)} - LoadI32(v + 4) + 1;
      } else if (attr == "compression" && type == "compression" && size == 1) {
        part.compression = static_cast<unsigned char>(v[0]);
      } else if (attr == "chunkCount" && type == "int" && size == 4) {
        part.chunk_count = LoadI32(v);
      } else if (attr == "tiles" && type == "tiledesc" && size == 9) {
        part.tile_x = static_cast<uint32_t>(LoadI32(v));
        part.tile_y = static_cast<uint32_t>(LoadI32(v + 4));
      } else if (attr == "type" && type == "string") {
        const std::string t(v, static_cast<size_t>(size));
        part.has_tiles = t == "tiledimage" || t == "deeptile";
      } else if (attr == "channels" && type == "chlist") {
        // name\0 then 16 bytes (pixel type, pLinear, reserved, x and y sampling) per channel.
        for (size_t c = 0; v[c] != '\0'; ++part.channels) c = std::strlen(v + c) + c + 1 + 16;
      }
      pos += static_cast<size_t>(size);
    }
    parts.push_back(part);
    if (!multipart) break;
  }
  uint64_t chunks = 0;
  for (const ExrPartLayout& p : parts) {
    if (!p.has_window) continue;  // OpenEXR refuses a header without its data window
    // At 2 bytes per value (half, the smallest), the pixels are at most the compression's
    // largest ratio times the file's bytes.
    const double values =
        static_cast<double>(p.w) * static_cast<double>(p.h) * static_cast<double>(std::max<int64_t>(p.channels, 1));
    if (p.w < 1 || p.h < 1 || 2.0 * values > MaxCompressionRatio(p.compression) * static_cast<double>(n)) {
      refuse(fmt::format("a data window of {} x {} with {} channels is more than {} bytes can hold", p.w, p.h,
                         p.channels, n));
    }
    uint64_t c = 0;
    if (p.chunk_count >= 0) {
      c = static_cast<uint64_t>(p.chunk_count);
    } else if (p.has_tiles && p.tile_x > 0 && p.tile_y > 0) {
      c = static_cast<uint64_t>((p.w + p.tile_x - 1) / p.tile_x) * static_cast<uint64_t>((p.h + p.tile_y - 1) / p.tile_y);
    } else if (!p.has_tiles) {
      const int64_t lines = LinesPerChunk(p.compression);
      c = static_cast<uint64_t>((p.h + lines - 1) / lines);
    }
    chunks += c;
    if (chunks > (n - pos) / 8) {
      refuse(fmt::format("{} chunks need {} bytes of offsets, {} are left", chunks, 8 * chunks, n - pos));
    }
  }
}

}  // namespace

namespace {

Imf::Header MakeHeader(const ExrImage& img) {
  SKYBAKE_CHECK(img.width > 0 && img.height > 0);
  SKYBAKE_CHECK_EQ(img.pixels.size(), static_cast<size_t>(img.width) * img.height * img.channels.size());
  Imf::Header header(img.width, img.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const std::string& c : img.channels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  for (const auto& [k, v] : img.strings) header.insert(k, Imf::StringAttribute(v));
  for (const auto& [k, v] : img.doubles) header.insert(k, Imf::DoubleAttribute(v));
  for (const auto& [k, v] : img.ints) header.insert(k, Imf::IntAttribute(v));
  for (const auto& [k, v] : img.float_vectors) header.insert(k, Imf::FloatVectorAttribute(v));
  if (img.chromaticities) Imf::addChromaticities(header, *img.chromaticities);
  return header;
}

Imf::FrameBuffer MakeFrameBuffer(const ExrImage& img) {
  Imf::FrameBuffer fb;
  const size_t nch = img.channels.size();
  const size_t xstride = sizeof(float) * nch;
  const size_t ystride = xstride * static_cast<size_t>(img.width);
  for (size_t c = 0; c < nch; ++c) {
    fb.insert(img.channels[c], Imf::Slice(Imf::FLOAT, (char*)(img.pixels.data() + c), xstride, ystride));
  }
  return fb;
}

// Fills `img` (header attributes, channels, pixels) from a part's header; returns the frame
// buffer to read into.
// A header whose data window holds more values than `file_bytes` can encode is refused before
// anything is allocated: deflate (ZIP) compresses at most ~1032:1 and a value takes at least 2
// bytes (half), so a file of n bytes holds at most ~516 n values (4096 n allowed here).
Imf::FrameBuffer PrepareRead(const Imf::Header& h, ExrImage& img, size_t file_bytes, const std::string& name) {
  Imath::Box2i dw = h.dataWindow();
  const int64_t w = int64_t{dw.max.x} - dw.min.x + 1, ht = int64_t{dw.max.y} - dw.min.y + 1;
  int64_t nch_declared = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) ++nch_declared;
  if (w < 1 || ht < 1 || w > (int64_t{1} << 30) || ht > (int64_t{1} << 30) ||
      static_cast<double>(w) * static_cast<double>(ht) * static_cast<double>(std::max<int64_t>(nch_declared, 1)) >
          4096.0 * static_cast<double>(file_bytes)) {
    throw InputError(FileLoc{name, 0}, fmt::format("not a readable OpenEXR file: a data window of {} x {} with {} "
                                                   "channels is more than {} bytes can hold",
                                                   w, ht, nch_declared, file_bytes));
  }
  img.width = static_cast<int>(w);
  img.height = static_cast<int>(ht);
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) img.channels.push_back(it.name());
  for (auto it = h.begin(); it != h.end(); ++it) {
    const std::string key = it.name();
    if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) img.strings[key] = s->value();
    else if (auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&it.attribute())) img.doubles[key] = d->value();
    else if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&it.attribute())) img.ints[key] = i->value();
    else if (auto* f = dynamic_cast<const Imf::FloatVectorAttribute*>(&it.attribute())) img.float_vectors[key] = f->value();
  }
  if (Imf::hasChromaticities(h)) img.chromaticities = Imf::chromaticities(h);
  img.pixels.assign(static_cast<size_t>(img.width) * img.height * img.channels.size(), 0.0f);
  Imf::FrameBuffer fb;
  const size_t nch = img.channels.size();
  const size_t xstride = sizeof(float) * nch;
  const size_t ystride = xstride * static_cast<size_t>(img.width);
  // Slice::Make places the data window's origin at the first pixel with integer arithmetic: a
  // base pointer computed as pixels - origin would point outside the buffer (undefined
  // behaviour for any data window not at 0,0).
  for (size_t c = 0; c < nch; ++c) {
    fb.insert(img.channels[c], Imf::Slice::Make(Imf::FLOAT, img.pixels.data() + c, dw, xstride, ystride));
  }
  return fb;
}

}  // namespace

std::string EncodeExr(const ExrImage& img) {
  Imf::Header header = MakeHeader(img);
  Imf::FrameBuffer fb = MakeFrameBuffer(img);
  MemOStream os;
  {
    Imf::OutputFile out(os, header, 1);
    out.setFrameBuffer(fb);
    out.writePixels(img.height);
  }
  return std::move(os.data());
}

bool WriteExr(const std::filesystem::path& path, const ExrImage& image) {
  return WriteFileIfChanged(path, EncodeExr(image));
}

ExrImage DecodeExr(const std::string& bytes, const std::string& name) {
  ExrImage img;
  CheckExrLayout(bytes, name);
  try {
    MemIStream is(bytes, name);
    Imf::InputFile in(is, 1);
    Imf::FrameBuffer fb = PrepareRead(in.header(), img, bytes.size(), name);
    in.setFrameBuffer(fb);
    Imath::Box2i dw = in.header().dataWindow();
    in.readPixels(dw.min.y, dw.max.y);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(FileLoc{name, 0}, std::string("not a readable OpenEXR file: ") + e.what());
  }
  return img;
}

std::string EncodeExrParts(const std::vector<ExrPart>& parts) {
  SKYBAKE_CHECK(!parts.empty());
  std::vector<Imf::Header> headers;
  for (const ExrPart& p : parts) {
    Imf::Header h = MakeHeader(p.image);
    h.setName(p.name);
    h.setType(Imf::SCANLINEIMAGE);
    // Multi-part files require identical shared attributes: every part takes the first part's
    // display window (each keeps its own data window, which is what holds the pixels).
    if (!headers.empty()) h.displayWindow() = headers.front().displayWindow();
    headers.push_back(h);
  }
  MemOStream os;
  {
    Imf::MultiPartOutputFile out(os, headers.data(), static_cast<int>(headers.size()), false, 1);
    for (size_t i = 0; i < parts.size(); ++i) {
      Imf::OutputPart part(out, static_cast<int>(i));
      Imf::FrameBuffer fb = MakeFrameBuffer(parts[i].image);
      part.setFrameBuffer(fb);
      part.writePixels(parts[i].image.height);
    }
  }
  return std::move(os.data());
}

bool WriteExrParts(const std::filesystem::path& path, const std::vector<ExrPart>& parts) {
  return WriteFileIfChanged(path, EncodeExrParts(parts));
}

std::vector<ExrPart> DecodeExrParts(const std::string& bytes, const std::string& name) {
  std::vector<ExrPart> parts;
  CheckExrLayout(bytes, name);
  try {
    MemIStream is(bytes, name);
    Imf::MultiPartInputFile in(is, 1);
    for (int i = 0; i < in.parts(); ++i) {
      ExrPart p;
      const Imf::Header& h = in.header(i);
      p.name = h.hasName() ? h.name() : std::string();
      Imf::InputPart part(in, i);
      Imf::FrameBuffer fb = PrepareRead(h, p.image, bytes.size(), name);
      part.setFrameBuffer(fb);
      Imath::Box2i dw = h.dataWindow();
      part.readPixels(dw.min.y, dw.max.y);
      parts.push_back(std::move(p));
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(FileLoc{name, 0}, std::string("not a readable OpenEXR file: ") + e.what());
  }
  return parts;
}

std::vector<ExrPart> ReadExrParts(const std::filesystem::path& path) {
  return DecodeExrParts(ReadFileBytes(path), path.string());
}

const ExrImage& FindPart(const std::vector<ExrPart>& parts, const std::string& part_name,
                         const std::string& display_name) {
  for (const ExrPart& p : parts) {
    if (p.name == part_name) return p.image;
  }
  throw InputError(FileLoc{display_name, 0}, "no part named '" + part_name + "'");
}

ExrImage ReadExr(const std::filesystem::path& path) {
  return DecodeExr(ReadFileBytes(path), path.string());
}

}  // namespace skybake
