// KTX 2.0 containers for GPU textures, written (and read back) by hand.
//
// Debian 12 packages no libktx, so skybake writes KTX2 itself. Everything here follows the KTX
// File Format Specification 2.0 (KhronosGroup/KTX-Specification ktxspec.adoc, "File Structure", "Data Format Descriptor", "Key/Value Data") and the Khronos Data
// Format Specification 1.3 basic descriptor block (the layout KTX-Software's lib/dfdutils writes):
//
//   identifier «KTX 20»\r\n\x1A\n (12 bytes)
//   header     vkFormat, typeSize, pixelWidth, pixelHeight, pixelDepth, layerCount, faceCount,
//              levelCount, supercompressionScheme                  (9 x UInt32, little-endian)
//   index      dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (UInt32),
//              sgdByteOffset, sgdByteLength (UInt64)
//   level index {byteOffset, byteLength, uncompressedByteLength} (UInt64) per level
//   DFD        dfdTotalSize + one basic descriptor block
//   KVD        {UInt32 keyAndValueByteLength; key NUL value; pad to 4} sorted by key
//   levels     each aligned to lcm(texel block size, 4); rows tightly packed;
//              order layer -> face -> z slice -> row -> texel
//
// What the writer supports (enough for every skybake product; a later lut-pack adds formats by
// adding a Format factory, see B10G11R11UfloatPack32()):
//   - any uncompressed vkFormat described by a Format {vkFormat, typeSize, texel bytes, DFD};
//   - 1D, 2D, 3D, 2D-array (and 1D/3D array, cube maps by faces = 6);
//   - exactly one mip level (levelCount = 1: "the texture isn't meant to have other levels",
//     ktxspec §levelCount - a LUT), no supercompression (scheme 0), no global data;
//   - key/value data: KTXwriter (always, "strongly encouraged") plus any caller keys, written in
//     key byte order (= Unicode code point order for UTF-8), each key unique.
// Files are little-endian; skybake only builds on little-endian hosts (checked at compile time).
//
// DecodeKtx2 is an independent, strict reader of the same subset: it validates every header and
// index field against the specification (offsets, alignment, padding, DFD length, sort order,
// level length) and reports the first violation as InputError(file). Tests also read the files
// with the npm `ktx-parse` package (tests/cli), a parser written by someone else.
//
// Texel encoders for the formats skybake writes are here too: float -> binary16 with
// round-to-nearest-even (our own, tested exhaustively against HalfToFloat) and float -> UNORM8.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "io/exr.h"

static_assert(std::endian::native == std::endian::little, "KTX2 writing assumes a little-endian host");

namespace skybake::ktx2 {

// VkFormat values used by skybake (Vulkan 1.0 core, vulkan_core.h `VkFormat`).
enum class VkFormat : uint32_t {
  kUndefined = 0,
  kR8Unorm = 9,
  kR8G8Unorm = 16,
  kR8G8B8A8Unorm = 37,
  kR16Sfloat = 76,
  kR16G16B16A16Sfloat = 97,
  kR32Sfloat = 100,
  kR32G32B32A32Sfloat = 109,
  kB10G11R11UfloatPack32 = 122,
};

// Khronos Data Format Specification 1.3 constants (khr_df.h names in comments).
namespace df {
inline constexpr uint32_t kVendorKhronos = 0;           // KHR_DF_VENDORID_KHRONOS
inline constexpr uint32_t kDescriptorBasicFormat = 0;   // KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT
inline constexpr uint32_t kVersion13 = 2;               // KHR_DF_VERSIONNUMBER_1_3
inline constexpr uint8_t kModelRgbsda = 1;              // KHR_DF_MODEL_RGBSDA
inline constexpr uint8_t kPrimariesUnspecified = 0;     // KHR_DF_PRIMARIES_UNSPECIFIED
inline constexpr uint8_t kPrimariesBt709 = 1;           // KHR_DF_PRIMARIES_BT709
inline constexpr uint8_t kTransferUnspecified = 0;      // KHR_DF_TRANSFER_UNSPECIFIED
inline constexpr uint8_t kTransferLinear = 1;           // KHR_DF_TRANSFER_LINEAR
inline constexpr uint8_t kTransferSrgb = 2;             // KHR_DF_TRANSFER_SRGB
inline constexpr uint8_t kFlagAlphaStraight = 0;        // KHR_DF_FLAG_ALPHA_STRAIGHT
inline constexpr uint8_t kChannelRed = 0;               // KHR_DF_CHANNEL_RGBSDA_RED
inline constexpr uint8_t kChannelGreen = 1;             // KHR_DF_CHANNEL_RGBSDA_GREEN
inline constexpr uint8_t kChannelBlue = 2;              // KHR_DF_CHANNEL_RGBSDA_BLUE
inline constexpr uint8_t kChannelAlpha = 15;            // KHR_DF_CHANNEL_RGBSDA_ALPHA
// Sample qualifiers (the high nibble of channelType).
inline constexpr uint8_t kQualifierLinear = 0x10;       // KHR_DF_SAMPLE_DATATYPE_LINEAR
inline constexpr uint8_t kQualifierExponent = 0x20;     // KHR_DF_SAMPLE_DATATYPE_EXPONENT
inline constexpr uint8_t kQualifierSigned = 0x40;       // KHR_DF_SAMPLE_DATATYPE_SIGNED
inline constexpr uint8_t kQualifierFloat = 0x80;        // KHR_DF_SAMPLE_DATATYPE_FLOAT
}  // namespace df

// One sample of a basic descriptor block (KDF 1.3 §5.18): 16 bytes.
struct DfdSample {
  uint16_t bit_offset = 0;
  uint8_t bit_length = 0;    // number of bits (the file stores bit_length - 1)
  uint8_t channel_type = 0;  // channel id (low nibble) | qualifiers (high nibble)
  std::array<uint8_t, 4> sample_position{};
  uint32_t lower = 0;        // sampleLower (bit pattern; a float's bits for FLOAT samples)
  uint32_t upper = 0;        // sampleUpper
  bool operator==(const DfdSample&) const = default;
};

// A basic data format descriptor block (KDF 1.3 §5): 24 bytes + 16 per sample.
struct BasicDfd {
  uint8_t color_model = df::kModelRgbsda;
  uint8_t color_primaries = df::kPrimariesBt709;
  uint8_t transfer_function = df::kTransferLinear;
  uint8_t flags = df::kFlagAlphaStraight;
  std::array<uint8_t, 4> texel_block_dimension{};  // each "size - 1": 0 = 1x1x1x1 texel blocks
  std::array<uint8_t, 8> bytes_plane{};
  std::vector<DfdSample> samples;
  bool operator==(const BasicDfd&) const = default;
};

// How the bits of a sample are interpreted (the Vulkan format's numeric suffix).
enum class Numeric { kUnorm, kSfloat, kUfloat };

// DFD of an unpacked little-endian format with `channels` components (R, G, B, A in memory order)
// of `bytes_per_channel` bytes each - KTX-Software dfdutils createDFDUnpacked(bigEndian = 0):
// one sample per channel at bitOffset 8*bytes*i, bitLength 8*bytes; UNORM: lower 0, upper
// 2^bits - 1; SFLOAT: qualifiers FLOAT|SIGNED, lower -1.0f, upper 1.0f; UFLOAT: FLOAT, 0.0f, 1.0f.
// Primaries BT.709, transfer linear, straight alpha (createdfd.c writeHeader).
BasicDfd UnpackedDfd(int channels, int bytes_per_channel, Numeric numeric);

// One channel of a packed format, listed from bit 0 of the packed word upwards.
struct PackedChannel {
  uint8_t channel_id;  // df::kChannelRed ...
  int bits;
};
// DFD of a packed little-endian format (dfdutils createDFDPacked(bigEndian = 0)): one sample per
// channel at increasing bit offsets, bytesPlane0 = total bits / 8.
BasicDfd PackedDfd(const std::vector<PackedChannel>& channels, Numeric numeric);

// A texel format: what the header and the DFD say, and how big a texel is.
struct Format {
  VkFormat vk_format = VkFormat::kUndefined;
  uint32_t type_size = 1;         // header typeSize (ktxspec §typeSize)
  uint32_t texel_block_bytes = 0; // bytes per texel (uncompressed: the texel block size)
  int channels = 0;               // components per texel
  std::string name;               // "R8_UNORM", ...
  BasicDfd dfd;
};

// The formats skybake writes; each is the Vulkan format's definition (typeSize per ktxspec: the
// bytes of one component, or xx/8 for _PACKxx) with its dfdutils DFD.
Format R8Unorm();
Format R8G8Unorm();
Format R8G8B8A8Unorm();
Format R16Sfloat();
Format R16G16B16A16Sfloat();
Format R32Sfloat();
Format R32G32B32A32Sfloat();
// VK_FORMAT_B10G11R11_UFLOAT_PACK32 (122): R in bits 0-10, G in 11-21, B in 22-31, unsigned
// floats; typeSize 4; DFD values as KTX-Software lib/dfdutils writes them (vk2dfd.inl,
// createdfd.c).
// The texel packing itself belongs to lut-pack.
Format B10G11R11UfloatPack32();
// The Format for a vkFormat above; throws InternalError for any other value.
Format FormatFor(VkFormat vk_format);

// A texture with one mip level.
struct Texture {
  Format format;
  uint32_t width = 0;   // pixelWidth (> 0)
  uint32_t height = 0;  // pixelHeight (0 for 1D)
  uint32_t depth = 0;   // pixelDepth (0 unless 3D)
  uint32_t layers = 0;  // layerCount (0 = not an array)
  uint32_t faces = 1;   // faceCount (6 for cube maps)
  // Identifies the writing tool: written as KTXwriter, e.g. "skybake noise-gen 0.1.0".
  std::string writer;
  // Further key/value data (keys must not start with "KTX"/"ktx" except KTXorientation and
  // KTXswizzle); values are raw bytes - use SetString for NUL-terminated UTF-8 strings.
  std::map<std::string, std::string> metadata;
  // Level 0: layer -> face -> z -> y -> x, texels tightly packed, little-endian.
  std::string data;

  // Bytes that `data` must hold for these dimensions and format.
  size_t ExpectedDataBytes() const;
  // A metadata string value without its NUL terminator ("" if absent).
  std::string GetString(const std::string& key) const;
};

// Sets metadata[key] to value + NUL (ktxspec: string values should be NUL terminated).
void SetString(Texture& texture, const std::string& key, const std::string& value);
// The provenance of an EXR product (io/exr.h SetProvenance) as key/value strings with the same
// names and formats: skybake.tool, skybake.version, skybake.parameters, skybake.inputs; and
// writer = "skybake <tool> <version>" (KTXwriter).
void SetProvenance(Texture& texture, const Provenance& provenance);

// Bytes of the encoded file. Throws InternalError if the texture is inconsistent (bad dimension
// combination for ktxspec "Texture Type", wrong data size, reserved or duplicate keys, empty writer).
std::string EncodeKtx2(const Texture& texture);
// EncodeKtx2 + WriteFileIfChanged; returns true when the file changed.
bool WriteKtx2(const std::filesystem::path& path, const Texture& texture);

// Parses and validates a KTX2 file of the supported subset (one level, no supercompression).
// KTXwriter comes back in `writer` (without NUL), every other key in `metadata`. The format is
// FormatFor(vkFormat) when skybake knows the vkFormat (and the file's DFD must then equal it),
// else a Format with the file's header values and DFD. Throws InputError(display_name).
Texture DecodeKtx2(const std::string& bytes, const std::string& display_name);
Texture ReadKtx2(const std::filesystem::path& path);

// The serialised DFD (dfdTotalSize first) and its parser (throws InputError(display_name)).
std::string EncodeDfd(const BasicDfd& dfd);
BasicDfd DecodeDfd(std::string_view bytes, const std::string& display_name);

// ---------------------------------------------------------------------------- texel encoders

// IEEE 754 binary32 -> binary16, round to nearest, ties to even, like a hardware conversion
// (IEEE 754-2008 §4.3.1 roundTiesToEven): magnitudes >= 65520 (half-way between the largest
// finite half 65504 and 2^16) become infinity, below 2^-14 give subnormals (steps of 2^-24),
// |x| <= 2^-25 gives a signed zero; NaN stays NaN (quiet, sign and top payload bits kept).
uint16_t FloatToHalf(float value);
// binary16 -> binary32 (exact: every half is a float).
float HalfToFloat(uint16_t half);
// [0, 1] -> UNORM8 code round(255 v) (Vulkan spec "Conversion from Floating-Point to Normalized
// Fixed-Point": round to nearest; here ties away from zero, deterministic); values outside [0, 1]
// are clamped and NaN gives 0.
uint8_t FloatToUnorm8(float value);
inline float Unorm8ToFloat(uint8_t code) { return static_cast<float>(code) / 255.0f; }

// Channel-interleaved float texels -> the bytes of `format` (little-endian): *_UNORM 8-bit via
// FloatToUnorm8, *_SFLOAT 16-bit via FloatToHalf, R32_SFLOAT as is. Each texel is encoded from its
// own float, so the bytes do not depend on how the floats were computed in parallel.
// values.size() must be a multiple of format.channels. Formats without a float encoder here
// (B10G11R11) throw InternalError: their packers belong to lut-pack.
std::string EncodeTexels(const Format& format, const std::vector<float>& values);
// The inverse (exact for the stored codes): bytes of `format` -> floats.
std::vector<float> DecodeTexels(const Format& format, const std::string& data);

}  // namespace skybake::ktx2
