// DirectDraw Surface (DDS) files with the DX10 header extension, written (and read back) by hand,
// for the Direct3D side of the LUTs (DXGI_FORMAT_R11G11B10_FLOAT). Layout, from Microsoft's
// "Programming Guide for DDS" (learn.microsoft.com/windows/win32/direct3ddds/dx-graphics-dds-pguide),
// "DDS_HEADER structure", "DDS_PIXELFORMAT structure" and "DDS_HEADER_DXT10 structure",
// all little-endian:
//
//   offset  0  dwMagic "DDS " (0x20534444)
//   offset  4  DDS_HEADER (124 bytes): dwSize = 124, dwFlags, dwHeight, dwWidth,
//              dwPitchOrLinearSize, dwDepth, dwMipMapCount, dwReserved1[11],
//              ddspf (32 bytes: dwSize = 32, dwFlags, dwFourCC, dwRGBBitCount, 4 masks),
//              dwCaps, dwCaps2, dwCaps3, dwCaps4, dwReserved2
//   offset 128 DDS_HEADER_DXT10 (20 bytes): dxgiFormat, resourceDimension, miscFlag, arraySize,
//              miscFlags2
//   offset 148 texels: array element -> depth slice -> row -> texel, rows tightly packed
//
// What we write (one mip level, no cube maps):
//   dwFlags = DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PIXELFORMAT (required in every file)
//             | DDSD_PITCH (uncompressed, pitch given) | DDSD_MIPMAPCOUNT (one level, stated)
//             | DDSD_DEPTH (3D only)
//   dwPitchOrLinearSize = width x bytes per texel; dwMipMapCount = 1; dwDepth = depth (3D) or 0
//   ddspf = {32, DDPF_FOURCC, "DX10", 0, 0, 0, 0, 0}
//   dwCaps = DDSCAPS_TEXTURE; dwCaps2 = DDSCAPS2_VOLUME for 3D, else 0
//   DXT10: resourceDimension 3 (TEXTURE2D) or 4 (TEXTURE3D); miscFlag 0; arraySize = layers for a
//          2D array (1 for a plain 2D texture) and 1 for 3D ("For a 3D texture, you must set this
//          number to 1"); miscFlags2 = DDS_ALPHA_MODE_UNKNOWN (0).
// OIIO 2.4 cannot read DX10 DDS files (notes §4.3), so the tests check the header field by field
// (tests/lut/dds_test.cpp in C++, tests/cli/test_lut_pack.py with Python's struct).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace skybake::dds {

inline constexpr uint32_t kMagic = 0x20534444u;  // "DDS "
// DDS_HEADER.dwFlags
inline constexpr uint32_t kDdsdCaps = 0x1, kDdsdHeight = 0x2, kDdsdWidth = 0x4, kDdsdPitch = 0x8,
                          kDdsdPixelFormat = 0x1000, kDdsdMipMapCount = 0x20000, kDdsdLinearSize = 0x80000,
                          kDdsdDepth = 0x800000;
// DDS_PIXELFORMAT.dwFlags
inline constexpr uint32_t kDdpfFourCc = 0x4;
inline constexpr uint32_t kFourCcDx10 = 0x30315844u;  // "DX10"
// dwCaps, dwCaps2
inline constexpr uint32_t kDdsCapsComplex = 0x8, kDdsCapsTexture = 0x1000, kDdsCapsMipmap = 0x400000;
inline constexpr uint32_t kDdsCaps2Volume = 0x200000;
// DDS_HEADER_DXT10.resourceDimension
inline constexpr uint32_t kDimensionTexture2D = 3, kDimensionTexture3D = 4;
// DXGI_FORMAT (dxgiformat.h)
inline constexpr uint32_t kDxgiFormatR11G11B10Float = 26;

inline constexpr size_t kHeaderBytes = 4 + 124 + 20;

struct Texture {
  uint32_t dxgi_format = kDxgiFormatR11G11B10Float;
  uint32_t bytes_per_texel = 4;
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t depth = 0;       // > 0: a 3D texture (then array_size must be 1)
  uint32_t array_size = 1;  // 2D: number of layers (1 = a plain 2D texture)
  std::string data;         // layer -> z -> y -> x, tightly packed

  bool Is3D() const { return depth > 0; }
  size_t ExpectedDataBytes() const;
};

// The file's bytes; InternalError for an inconsistent texture (zero sizes, wrong data length,
// a 3D texture with array_size != 1).
std::string EncodeDds(const Texture& texture);
// EncodeDds + WriteFileIfChanged; true when the file changed.
bool WriteDds(const std::filesystem::path& path, const Texture& texture);
// Parses and validates a file of the subset above (DX10 header, one mip level, 2D/2D array/3D),
// checking every field listed; InputError(display_name) naming the first bad field.
// bytes_per_texel is known only for R11G11B10_FLOAT (4); other formats are refused.
Texture DecodeDds(const std::string& bytes, const std::string& display_name);

}  // namespace skybake::dds
