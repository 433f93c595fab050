#include "lut/ktx2.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include <fmt/format.h>

#include "io/error.h"
#include "io/fileio.h"
#include "skybake/version.h"

namespace skybake::ktx2 {

namespace {

// ktxspec "identifier".
constexpr std::array<uint8_t, 12> kIdentifier = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32,
                                                 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
constexpr size_t kHeaderBytes = 12 + 9 * 4;         // identifier + 9 UInt32
constexpr size_t kIndexBytes = 4 * 4 + 2 * 8;        // dfd/kvd offsets+lengths, sgd offset+length
constexpr size_t kLevelIndexEntryBytes = 3 * 8;      // byteOffset, byteLength, uncompressedByteLength
constexpr size_t kDfdBlockHeaderBytes = 24;          // KDF basic block before the samples
constexpr size_t kDfdSampleBytes = 16;

void PutU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void PutU64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
uint32_t GetU32(std::string_view in, size_t pos) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(static_cast<uint8_t>(in[pos + i])) << (8 * i);
  return v;
}
uint64_t GetU64(std::string_view in, size_t pos) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(static_cast<uint8_t>(in[pos + i])) << (8 * i);
  return v;
}
size_t AlignUp(size_t v, size_t a) { return (v + a - 1) / a * a; }

uint32_t FloatBits(float f) { return std::bit_cast<uint32_t>(f); }

// ktxspec "mipPadding": levels align to lcm(texel block size, 4) without supercompression.
size_t LevelAlignment(const Format& f) { return std::lcm(static_cast<size_t>(f.texel_block_bytes), size_t{4}); }

// Keys the KTX spec defines (may start with "KTX"); KTXwriter is written from Texture::writer.
bool IsPredefinedKey(const std::string& key) {
  return key == "KTXorientation" || key == "KTXswizzle" || key == "KTXcubemapIncomplete" ||
         key == "KTXanimData" || key == "KTXastcDecodeMode" || key == "KTXglFormat" ||
         key == "KTXdxgiFormat__" || key == "KTXmetalPixelFormat";
}
bool IsReservedPrefix(const std::string& key) {
  return key.size() >= 3 && (key.compare(0, 3, "KTX") == 0 || key.compare(0, 3, "ktx") == 0);
}

// ktxspec "Texture Type": the valid (width, height, depth, layers, faces) combinations.
std::string TextureTypeProblem(uint32_t w, uint32_t h, uint32_t d, uint32_t faces) {
  if (w == 0) return "pixelWidth must not be 0";
  if (faces != 1 && faces != 6) return fmt::format("faceCount must be 1 or 6, got {}", faces);
  if (d > 0 && h == 0) return "a 3D texture (pixelDepth > 0) needs pixelHeight > 0";
  if (faces == 6 && (h != w || d != 0)) return "a cube map needs pixelHeight = pixelWidth and pixelDepth = 0";
  return "";
}

// A sample's qualifiers, sampleLower and sampleUpper (KDF 1.3 §5, basic descriptor block): UNORM 0 .. 2^bits - 1;
// SFLOAT -1 .. 1 and UFLOAT 0 .. 1 as the floats' bit patterns, with the FLOAT (and SIGNED) qualifier.
void SetSampleRange(Numeric numeric, int bits, DfdSample* s) {
  switch (numeric) {
    case Numeric::kUnorm:
      s->lower = 0;
      s->upper = bits >= 32 ? 0xFFFFFFFFu : (1u << bits) - 1u;
      break;
    case Numeric::kSfloat:
      s->channel_type |= df::kQualifierFloat | df::kQualifierSigned;
      s->lower = FloatBits(-1.0f);
      s->upper = FloatBits(1.0f);
      break;
    case Numeric::kUfloat:
      s->channel_type |= df::kQualifierFloat;
      s->lower = FloatBits(0.0f);
      s->upper = FloatBits(1.0f);
      break;
  }
}

}  // namespace

// ---------------------------------------------------------------------------- DFDs

BasicDfd UnpackedDfd(int channels, int bytes_per_channel, Numeric numeric) {
  SKYBAKE_CHECK(channels >= 1 && channels <= 4);
  SKYBAKE_CHECK(bytes_per_channel >= 1 && bytes_per_channel <= 4);
  BasicDfd dfd;
  dfd.bytes_plane[0] = static_cast<uint8_t>(channels * bytes_per_channel);
  static constexpr uint8_t kIds[4] = {df::kChannelRed, df::kChannelGreen, df::kChannelBlue, df::kChannelAlpha};
  for (int c = 0; c < channels; ++c) {
    DfdSample s;
    const int bits = 8 * bytes_per_channel;
    s.bit_offset = static_cast<uint16_t>(8 * bytes_per_channel * c);
    s.bit_length = static_cast<uint8_t>(bits);
    s.channel_type = kIds[c];
    SetSampleRange(numeric, bits, &s);
    dfd.samples.push_back(s);
  }
  return dfd;
}

BasicDfd PackedDfd(const std::vector<PackedChannel>& channels, Numeric numeric) {
  SKYBAKE_CHECK(!channels.empty() && channels.size() <= 4);
  BasicDfd dfd;
  int offset = 0;
  for (const PackedChannel& ch : channels) {
    SKYBAKE_CHECK(ch.bits >= 1 && ch.bits <= 32);
    DfdSample s;
    s.bit_offset = static_cast<uint16_t>(offset);
    s.bit_length = static_cast<uint8_t>(ch.bits);
    s.channel_type = ch.channel_id;
    SetSampleRange(numeric, ch.bits, &s);
    dfd.samples.push_back(s);
    offset += ch.bits;
  }
  SKYBAKE_CHECK_EQ(offset % 8, 0);
  dfd.bytes_plane[0] = static_cast<uint8_t>(offset / 8);
  return dfd;
}

namespace {
Format MakeUnpacked(VkFormat vk, const char* name, int channels, int bytes, Numeric numeric) {
  Format f;
  f.vk_format = vk;
  f.type_size = static_cast<uint32_t>(bytes);
  f.texel_block_bytes = static_cast<uint32_t>(channels * bytes);
  f.channels = channels;
  f.name = name;
  f.dfd = UnpackedDfd(channels, bytes, numeric);
  return f;
}
}  // namespace

Format R8Unorm() { return MakeUnpacked(VkFormat::kR8Unorm, "R8_UNORM", 1, 1, Numeric::kUnorm); }
Format R8G8Unorm() { return MakeUnpacked(VkFormat::kR8G8Unorm, "R8G8_UNORM", 2, 1, Numeric::kUnorm); }
Format R8G8B8A8Unorm() { return MakeUnpacked(VkFormat::kR8G8B8A8Unorm, "R8G8B8A8_UNORM", 4, 1, Numeric::kUnorm); }
Format R16Sfloat() { return MakeUnpacked(VkFormat::kR16Sfloat, "R16_SFLOAT", 1, 2, Numeric::kSfloat); }
Format R16G16B16A16Sfloat() {
  return MakeUnpacked(VkFormat::kR16G16B16A16Sfloat, "R16G16B16A16_SFLOAT", 4, 2, Numeric::kSfloat);
}
Format R32Sfloat() { return MakeUnpacked(VkFormat::kR32Sfloat, "R32_SFLOAT", 1, 4, Numeric::kSfloat); }
Format R32G32B32A32Sfloat() {
  return MakeUnpacked(VkFormat::kR32G32B32A32Sfloat, "R32G32B32A32_SFLOAT", 4, 4, Numeric::kSfloat);
}

Format B10G11R11UfloatPack32() {
  Format f;
  f.vk_format = VkFormat::kB10G11R11UfloatPack32;
  f.type_size = 4;  // _PACK32: 32 / 8
  f.texel_block_bytes = 4;
  f.channels = 3;
  f.name = "B10G11R11_UFLOAT_PACK32";
  f.dfd = PackedDfd({{df::kChannelRed, 11}, {df::kChannelGreen, 11}, {df::kChannelBlue, 10}}, Numeric::kUfloat);
  return f;
}

Format FormatFor(VkFormat vk) {
  switch (vk) {
    case VkFormat::kR8Unorm: return R8Unorm();
    case VkFormat::kR8G8Unorm: return R8G8Unorm();
    case VkFormat::kR8G8B8A8Unorm: return R8G8B8A8Unorm();
    case VkFormat::kR16Sfloat: return R16Sfloat();
    case VkFormat::kR16G16B16A16Sfloat: return R16G16B16A16Sfloat();
    case VkFormat::kR32Sfloat: return R32Sfloat();
    case VkFormat::kR32G32B32A32Sfloat: return R32G32B32A32Sfloat();
    case VkFormat::kB10G11R11UfloatPack32: return B10G11R11UfloatPack32();
    case VkFormat::kUndefined: break;
  }
  throw InternalError(fmt::format("no KTX2 format description for vkFormat {}", static_cast<uint32_t>(vk)));
}

namespace {
bool IsKnownFormat(uint32_t vk) {
  switch (static_cast<VkFormat>(vk)) {
    case VkFormat::kR8Unorm:
    case VkFormat::kR8G8Unorm:
    case VkFormat::kR8G8B8A8Unorm:
    case VkFormat::kR16Sfloat:
    case VkFormat::kR16G16B16A16Sfloat:
    case VkFormat::kR32Sfloat:
    case VkFormat::kR32G32B32A32Sfloat:
    case VkFormat::kB10G11R11UfloatPack32:
      return true;
    case VkFormat::kUndefined:
      return false;
  }
  return false;
}
}  // namespace

std::string EncodeDfd(const BasicDfd& dfd) {
  const uint32_t block_size = static_cast<uint32_t>(kDfdBlockHeaderBytes + kDfdSampleBytes * dfd.samples.size());
  std::string out;
  PutU32(out, 4 + block_size);  // dfdTotalSize
  // Word 0: vendorId (17 bits) | descriptorType (15 bits) << 17.
  PutU32(out, df::kVendorKhronos | (df::kDescriptorBasicFormat << 17));
  // Word 1: versionNumber (16 bits) | descriptorBlockSize << 16.
  PutU32(out, df::kVersion13 | (block_size << 16));
  // Word 2: colorModel | colorPrimaries << 8 | transferFunction << 16 | flags << 24.
  PutU32(out, static_cast<uint32_t>(dfd.color_model) | static_cast<uint32_t>(dfd.color_primaries) << 8 |
                  static_cast<uint32_t>(dfd.transfer_function) << 16 | static_cast<uint32_t>(dfd.flags) << 24);
  for (uint8_t b : dfd.texel_block_dimension) out.push_back(static_cast<char>(b));
  for (uint8_t b : dfd.bytes_plane) out.push_back(static_cast<char>(b));
  for (const DfdSample& s : dfd.samples) {
    SKYBAKE_CHECK(s.bit_length >= 1);
    // bitOffset (16) | (bitLength - 1) << 16 (8) | channelType << 24 (8).
    PutU32(out, static_cast<uint32_t>(s.bit_offset) | static_cast<uint32_t>(s.bit_length - 1) << 16 |
                    static_cast<uint32_t>(s.channel_type) << 24);
    for (uint8_t b : s.sample_position) out.push_back(static_cast<char>(b));
    PutU32(out, s.lower);
    PutU32(out, s.upper);
  }
  return out;
}

BasicDfd DecodeDfd(std::string_view bytes, const std::string& display_name) {
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{display_name, 0}, "data format descriptor: " + msg); };
  if (bytes.size() < 4 + kDfdBlockHeaderBytes) fail("shorter than one basic descriptor block");
  const uint32_t total = GetU32(bytes, 0);
  if (total != bytes.size()) fail(fmt::format("dfdTotalSize {} differs from dfdByteLength {}", total, bytes.size()));
  const uint32_t w0 = GetU32(bytes, 4), w1 = GetU32(bytes, 8);
  if ((w0 & 0x1FFFF) != df::kVendorKhronos || (w0 >> 17) != df::kDescriptorBasicFormat)
    fail("the first block is not a Khronos basic descriptor block");
  if ((w1 & 0xFFFF) != df::kVersion13) fail(fmt::format("versionNumber {} is not 2 (KDF 1.3)", w1 & 0xFFFF));
  const uint32_t block_size = w1 >> 16;
  if (block_size + 4 != total) fail(fmt::format("descriptorBlockSize {} + 4 differs from dfdTotalSize {}", block_size, total));
  if (block_size < kDfdBlockHeaderBytes || (block_size - kDfdBlockHeaderBytes) % kDfdSampleBytes != 0)
    fail(fmt::format("descriptorBlockSize {} is not 24 + 16 x samples", block_size));
  BasicDfd dfd;
  const uint32_t w2 = GetU32(bytes, 12);
  dfd.color_model = static_cast<uint8_t>(w2);
  dfd.color_primaries = static_cast<uint8_t>(w2 >> 8);
  dfd.transfer_function = static_cast<uint8_t>(w2 >> 16);
  dfd.flags = static_cast<uint8_t>(w2 >> 24);
  for (int i = 0; i < 4; ++i) dfd.texel_block_dimension[i] = static_cast<uint8_t>(bytes[16 + i]);
  for (int i = 0; i < 8; ++i) dfd.bytes_plane[i] = static_cast<uint8_t>(bytes[20 + i]);
  const size_t n = (block_size - kDfdBlockHeaderBytes) / kDfdSampleBytes;
  for (size_t k = 0; k < n; ++k) {
    const size_t p = 4 + kDfdBlockHeaderBytes + k * kDfdSampleBytes;
    DfdSample s;
    const uint32_t sw = GetU32(bytes, p);
    s.bit_offset = static_cast<uint16_t>(sw & 0xFFFF);
    s.bit_length = static_cast<uint8_t>(((sw >> 16) & 0xFF) + 1);
    s.channel_type = static_cast<uint8_t>(sw >> 24);
    for (int i = 0; i < 4; ++i) s.sample_position[i] = static_cast<uint8_t>(bytes[p + 4 + i]);
    s.lower = GetU32(bytes, p + 8);
    s.upper = GetU32(bytes, p + 12);
    dfd.samples.push_back(s);
  }
  return dfd;
}

// ---------------------------------------------------------------------------- Texture

size_t Texture::ExpectedDataBytes() const {
  return static_cast<size_t>(width) * std::max<uint32_t>(1, height) * std::max<uint32_t>(1, depth) *
         std::max<uint32_t>(1, layers) * faces * format.texel_block_bytes;
}

std::string Texture::GetString(const std::string& key) const {
  auto it = metadata.find(key);
  if (it == metadata.end()) return "";
  std::string v = it->second;
  if (!v.empty() && v.back() == '\0') v.pop_back();
  return v;
}

void SetString(Texture& texture, const std::string& key, const std::string& value) {
  texture.metadata[key] = value + std::string(1, '\0');
}

void SetProvenance(Texture& texture, const Provenance& p) {
  texture.writer = "skybake " + p.tool + " " + kVersion;
  SetString(texture, "skybake.tool", p.tool);
  SetString(texture, "skybake.version", kVersion);
  SetString(texture, "skybake.parameters", p.parameters);
  std::string inputs;
  for (const auto& [path, hash] : p.inputs) inputs += path + " xxh3:" + hash + "\n";
  SetString(texture, "skybake.inputs", inputs);
}

std::string EncodeKtx2(const Texture& t) {
  if (std::string p = TextureTypeProblem(t.width, t.height, t.depth, t.faces); !p.empty()) throw InternalError("KTX2: " + p);
  SKYBAKE_CHECK(t.format.texel_block_bytes > 0);
  SKYBAKE_CHECK(t.format.type_size > 0);
  SKYBAKE_CHECK(!t.writer.empty());
  SKYBAKE_CHECK_EQ(t.data.size(), t.ExpectedDataBytes());

  // Key/value data: KTXwriter plus the caller's keys, sorted by key bytes (std::map order).
  std::map<std::string, std::string> kv = t.metadata;
  for (const auto& [key, value] : kv) {
    if (key.empty() || key.find('\0') != std::string::npos) throw InternalError("KTX2: empty key or NUL in key");
    if (key == "KTXwriter") throw InternalError("KTX2: set Texture::writer instead of a KTXwriter key");
    if (IsReservedPrefix(key) && !IsPredefinedKey(key)) throw InternalError("KTX2: key '" + key + "' uses the reserved KTX prefix");
  }
  kv["KTXwriter"] = t.writer + std::string(1, '\0');

  std::string kvd;
  for (const auto& [key, value] : kv) {
    const uint32_t len = static_cast<uint32_t>(key.size() + 1 + value.size());
    PutU32(kvd, len);
    kvd += key;
    kvd.push_back('\0');
    kvd += value;
    kvd.append(AlignUp(kvd.size(), 4) - kvd.size(), '\0');  // valuePadding
  }

  const std::string dfd = EncodeDfd(t.format.dfd);
  const size_t level_index_offset = kHeaderBytes + kIndexBytes;
  const size_t dfd_offset = level_index_offset + kLevelIndexEntryBytes;  // one level
  const size_t kvd_offset = dfd_offset + dfd.size();
  // No supercompression global data; the level follows the KVD after mipPadding.
  const size_t level_offset = AlignUp(kvd_offset + kvd.size(), LevelAlignment(t.format));

  std::string out(kIdentifier.begin(), kIdentifier.end());
  PutU32(out, static_cast<uint32_t>(t.format.vk_format));
  PutU32(out, t.format.type_size);
  PutU32(out, t.width);
  PutU32(out, t.height);
  PutU32(out, t.depth);
  PutU32(out, t.layers);
  PutU32(out, t.faces);
  PutU32(out, 1);  // levelCount
  PutU32(out, 0);  // supercompressionScheme: none
  PutU32(out, static_cast<uint32_t>(dfd_offset));
  PutU32(out, static_cast<uint32_t>(dfd.size()));
  PutU32(out, static_cast<uint32_t>(kvd_offset));
  PutU32(out, static_cast<uint32_t>(kvd.size()));
  PutU64(out, 0);  // sgdByteOffset
  PutU64(out, 0);  // sgdByteLength
  PutU64(out, level_offset);
  PutU64(out, t.data.size());  // byteLength
  PutU64(out, t.data.size());  // uncompressedByteLength (= byteLength without supercompression)
  SKYBAKE_CHECK_EQ(out.size(), dfd_offset);
  out += dfd;
  out += kvd;
  out.append(level_offset - out.size(), '\0');  // mipPadding
  out += t.data;
  return out;
}

bool WriteKtx2(const std::filesystem::path& path, const Texture& texture) {
  return WriteFileIfChanged(path, EncodeKtx2(texture));
}

Texture DecodeKtx2(const std::string& bytes, const std::string& display_name) {
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{display_name, 0}, "KTX2: " + msg); };
  const std::string_view in(bytes);
  if (in.size() < kHeaderBytes + kIndexBytes + kLevelIndexEntryBytes) fail("file too short for a KTX2 header");
  if (std::memcmp(in.data(), kIdentifier.data(), kIdentifier.size()) != 0) fail("missing the KTX 2.0 identifier");
  size_t p = 12;
  auto u32 = [&]() { uint32_t v = GetU32(in, p); p += 4; return v; };
  auto u64 = [&]() { uint64_t v = GetU64(in, p); p += 8; return v; };
  const uint32_t vk = u32(), type_size = u32(), width = u32(), height = u32(), depth = u32(), layers = u32(),
                 faces = u32(), level_count = u32(), scheme = u32();
  const uint32_t dfd_offset = u32(), dfd_length = u32(), kvd_offset = u32(), kvd_length = u32();
  const uint64_t sgd_offset = u64(), sgd_length = u64();
  if (level_count != 1) fail(fmt::format("levelCount {} is not supported (skybake reads one level)", level_count));
  if (scheme != 0) fail(fmt::format("supercompressionScheme {} is not supported", scheme));
  if (std::string prob = TextureTypeProblem(width, height, depth, faces); !prob.empty()) fail(prob);
  if (sgd_length != 0 || sgd_offset != 0) fail("supercompression global data must be absent (offset and length 0)");
  const uint64_t level_offset = u64(), level_length = u64(), level_uncompressed = u64();
  if (dfd_offset != p) fail(fmt::format("dfdByteOffset {} is not right after the level index ({})", dfd_offset, p));
  if (static_cast<size_t>(dfd_offset) + dfd_length > in.size()) fail("the DFD runs past the end of the file");
  const BasicDfd dfd = DecodeDfd(in.substr(dfd_offset, dfd_length), display_name);
  // ktxspec dfdTotalSize: dfdTotalSize != kvdByteOffset - dfdByteOffset makes the file invalid
  // (when there is key/value data; kvdByteOffset must be 0 without it).
  if (kvd_length == 0 && kvd_offset != 0) fail("kvdByteOffset must be 0 when kvdByteLength is 0");
  if (kvd_length > 0 && kvd_offset != dfd_offset + dfd_length)
    fail(fmt::format("kvdByteOffset {} is not dfdByteOffset + dfdTotalSize ({})", kvd_offset, dfd_offset + dfd_length));

  Texture t;
  if (IsKnownFormat(vk)) {
    t.format = FormatFor(static_cast<VkFormat>(vk));
    if (type_size != t.format.type_size)
      fail(fmt::format("typeSize {} does not match {} (expected {})", type_size, t.format.name, t.format.type_size));
    if (!(dfd == t.format.dfd)) fail("the DFD does not describe " + t.format.name);
  } else {
    t.format.vk_format = static_cast<VkFormat>(vk);
    t.format.type_size = type_size;
    t.format.texel_block_bytes = dfd.bytes_plane[0];
    t.format.channels = static_cast<int>(dfd.samples.size());
    t.format.name = fmt::format("vkFormat {}", vk);
    t.format.dfd = dfd;
    if (t.format.texel_block_bytes == 0) fail("bytesPlane0 is 0 (unsized formats are not supported)");
  }
  t.width = width;
  t.height = height;
  t.depth = depth;
  t.layers = layers;
  t.faces = faces;

  // Key/value data: {UInt32 length; key NUL value; padding to 4}, sorted, unique keys.
  size_t kv_end = static_cast<size_t>(kvd_offset) + kvd_length;
  if (kvd_length > 0 && kv_end > in.size()) fail("the key/value data runs past the end of the file");
  std::string previous_key;
  bool first = true;
  for (size_t q = kvd_offset; kvd_length > 0 && q < kv_end;) {
    if (q + 4 > kv_end) fail("truncated keyAndValueByteLength");
    const uint32_t len = GetU32(in, q);
    q += 4;
    if (len < 2) fail("keyAndValueByteLength below 2");
    if (q + len > kv_end) fail("a key/value pair runs past kvdByteLength");
    const std::string_view kvp = in.substr(q, len);
    const size_t nul = kvp.find('\0');
    if (nul == std::string_view::npos || nul == 0) fail("a key is empty or not NUL-terminated");
    std::string key(kvp.substr(0, nul));
    std::string value(kvp.substr(nul + 1));
    if (!first && !(previous_key < key)) fail("keys are not sorted (or repeat): '" + previous_key + "' before '" + key + "'");
    first = false;
    previous_key = key;
    q += len;
    const size_t padded = AlignUp(q, 4);
    if (padded > kv_end) fail("valuePadding runs past kvdByteLength");
    for (; q < padded; ++q) {
      if (in[q] != '\0') fail("valuePadding must be zero bytes");
    }
    if (key == "KTXwriter") {
      if (!value.empty() && value.back() == '\0') value.pop_back();
      t.writer = value;
    } else {
      t.metadata[key] = value;
    }
  }

  // The level: aligned, right after the KVD (+ mipPadding), exactly the expected size, last.
  const size_t after_kvd = kvd_length > 0 ? kv_end : static_cast<size_t>(dfd_offset) + dfd_length;
  const size_t expected_offset = AlignUp(after_kvd, LevelAlignment(t.format));
  if (level_offset != expected_offset)
    fail(fmt::format("level 0 byteOffset {} is not the next lcm(texel block size, 4) boundary after the key/value data ({})",
                     level_offset, expected_offset));
  if (expected_offset > in.size()) fail(fmt::format("the file has {} bytes and ends before level 0 ({})", in.size(), expected_offset));
  for (size_t q = after_kvd; q < expected_offset; ++q) {
    if (in[q] != '\0') fail("mipPadding must be zero bytes");
  }
  if (level_uncompressed != level_length) fail("uncompressedByteLength differs from byteLength without supercompression");
  if (level_length != t.ExpectedDataBytes())
    fail(fmt::format("level 0 holds {} bytes; {}x{}x{} x{} layers x{} faces of {} needs {}", level_length, width, height,
                     depth, layers, faces, t.format.name, t.ExpectedDataBytes()));
  if (level_offset + level_length != in.size())
    fail(fmt::format("the file has {} bytes; the level ends at {}", in.size(), level_offset + level_length));
  t.data = bytes.substr(level_offset, level_length);
  return t;
}

Texture ReadKtx2(const std::filesystem::path& path) { return DecodeKtx2(ReadFileBytes(path), path.string()); }

// ---------------------------------------------------------------------------- texel encoders

uint16_t FloatToHalf(float value) {
  const uint32_t x = std::bit_cast<uint32_t>(value);
  const uint16_t sign = static_cast<uint16_t>((x >> 16) & 0x8000u);
  const uint32_t ax = x & 0x7FFFFFFFu;
  if (ax >= 0x7F800000u) {  // infinity or NaN
    if (ax == 0x7F800000u) return sign | 0x7C00u;
    return static_cast<uint16_t>(sign | 0x7E00u | ((ax >> 13) & 0x3FFu));  // quiet NaN
  }
  // 65520 = 0x477FF000: the midpoint between 65504 (odd mantissa 0x3FF) and 2^16; ties go to the
  // even neighbour, which is infinity (mantissa 0), so everything from 65520 up overflows.
  if (ax >= 0x477FF000u) return sign | 0x7C00u;
  if (ax < 0x38800000u) {  // |x| < 2^-14: a subnormal half m * 2^-24 (or zero)
    // 2^-25 (0x33000000) is the midpoint between 0 and 2^-24; the tie goes to even (0).
    if (ax <= 0x33000000u) return sign;
    const uint32_t e = ax >> 23;                        // biased float exponent, 102..112
    const uint32_t mant = (ax & 0x7FFFFFu) | 0x800000u;  // 24-bit significand
    const uint32_t shift = 126u - e;                      // |x| = mant * 2^(e-150) = (mant >> shift) * 2^-24
    uint32_t m = mant >> shift;
    const uint32_t rem = mant & ((1u << shift) - 1u);
    const uint32_t halfway = 1u << (shift - 1u);
    if (rem > halfway || (rem == halfway && (m & 1u))) ++m;  // may carry into the smallest normal
    return static_cast<uint16_t>(sign | m);
  }
  // Normal: rebias the exponent (127 - 15 = 112) and round the 23-bit mantissa to 10 bits.
  const uint32_t r = ax - 0x38000000u;
  uint32_t h = r >> 13;
  const uint32_t rem = r & 0x1FFFu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h;  // a carry bumps the exponent correctly
  return static_cast<uint16_t>(sign | h);
}

float HalfToFloat(uint16_t half) {
  const uint32_t sign = (half & 0x8000u) ? 1u : 0u;
  const uint32_t e = (half >> 10) & 0x1Fu;
  const uint32_t m = half & 0x3FFu;
  float v;
  if (e == 0) {
    v = std::ldexp(static_cast<float>(m), -24);  // subnormal (or zero): m * 2^-24
  } else if (e == 31) {
    if (m == 0) {
      v = std::numeric_limits<float>::infinity();
    } else {
      return std::bit_cast<float>((sign << 31) | 0x7FC00000u | (m << 13));
    }
  } else {
    v = std::ldexp(static_cast<float>(1024u + m), static_cast<int>(e) - 25);  // (1 + m/1024) 2^(e-15)
  }
  return sign ? -v : v;
}

uint8_t FloatToUnorm8(float value) {
  if (!(value > 0.0f)) return 0;  // also NaN
  if (value >= 1.0f) return 255;
  return static_cast<uint8_t>(std::floor(static_cast<double>(value) * 255.0 + 0.5));
}

namespace {
enum class Codec { kUnorm8, kHalf, kFloat32 };
Codec CodecFor(const Format& f) {
  switch (f.vk_format) {
    case VkFormat::kR8Unorm:
    case VkFormat::kR8G8Unorm:
    case VkFormat::kR8G8B8A8Unorm:
      return Codec::kUnorm8;
    case VkFormat::kR16Sfloat:
    case VkFormat::kR16G16B16A16Sfloat:
      return Codec::kHalf;
    case VkFormat::kR32Sfloat:
    case VkFormat::kR32G32B32A32Sfloat:
      return Codec::kFloat32;
    default:
      break;
  }
  throw InternalError("no float texel encoder for " + f.name);
}
}  // namespace

std::string EncodeTexels(const Format& format, const std::vector<float>& values) {
  const Codec codec = CodecFor(format);
  SKYBAKE_CHECK_EQ(values.size() % static_cast<size_t>(format.channels), 0u);
  std::string out;
  switch (codec) {
    case Codec::kUnorm8:
      out.resize(values.size());
      for (size_t i = 0; i < values.size(); ++i) out[i] = static_cast<char>(FloatToUnorm8(values[i]));
      break;
    case Codec::kHalf:
      out.resize(values.size() * 2);
      for (size_t i = 0; i < values.size(); ++i) {
        const uint16_t h = FloatToHalf(values[i]);
        out[2 * i] = static_cast<char>(h & 0xFF);
        out[2 * i + 1] = static_cast<char>(h >> 8);
      }
      break;
    case Codec::kFloat32:
      out.resize(values.size() * 4);
      for (size_t i = 0; i < values.size(); ++i) {
        const uint32_t b = std::bit_cast<uint32_t>(values[i]);
        for (int k = 0; k < 4; ++k) out[4 * i + k] = static_cast<char>((b >> (8 * k)) & 0xFF);
      }
      break;
  }
  return out;
}

std::vector<float> DecodeTexels(const Format& format, const std::string& data) {
  const Codec codec = CodecFor(format);
  std::vector<float> out;
  switch (codec) {
    case Codec::kUnorm8:
      out.resize(data.size());
      for (size_t i = 0; i < data.size(); ++i) out[i] = Unorm8ToFloat(static_cast<uint8_t>(data[i]));
      break;
    case Codec::kHalf:
      SKYBAKE_CHECK_EQ(data.size() % 2, 0u);
      out.resize(data.size() / 2);
      for (size_t i = 0; i < out.size(); ++i) {
        out[i] = HalfToFloat(static_cast<uint16_t>(static_cast<uint8_t>(data[2 * i]) |
                                                   static_cast<uint8_t>(data[2 * i + 1]) << 8));
      }
      break;
    case Codec::kFloat32:
      SKYBAKE_CHECK_EQ(data.size() % 4, 0u);
      out.resize(data.size() / 4);
      for (size_t i = 0; i < out.size(); ++i) out[i] = std::bit_cast<float>(GetU32(data, 4 * i));
      break;
  }
  return out;
}

}  // namespace skybake::ktx2
