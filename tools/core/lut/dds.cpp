#include "lut/dds.h"

#include <fmt/format.h>

#include "io/error.h"
#include "io/fileio.h"

namespace skybake::dds {

namespace {

void PutU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}
uint32_t GetU32(const std::string& in, size_t pos) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(static_cast<uint8_t>(in[pos + i])) << (8 * i);
  return v;
}

uint32_t FlagsOf(const Texture& t) {
  uint32_t f = kDdsdCaps | kDdsdHeight | kDdsdWidth | kDdsdPixelFormat | kDdsdPitch | kDdsdMipMapCount;
  if (t.Is3D()) f |= kDdsdDepth;
  return f;
}

}  // namespace

size_t Texture::ExpectedDataBytes() const {
  return static_cast<size_t>(width) * height * (Is3D() ? depth : 1) * array_size * bytes_per_texel;
}

std::string EncodeDds(const Texture& t) {
  if (t.width == 0 || t.height == 0 || t.array_size == 0 || t.bytes_per_texel == 0) {
    throw InternalError(fmt::format("DDS: zero size ({}x{}, {} layers, {} bytes per texel)", t.width, t.height,
                                    t.array_size, t.bytes_per_texel));
  }
  if (t.Is3D() && t.array_size != 1) throw InternalError("DDS: a 3D texture must have arraySize 1");
  if (t.data.size() != t.ExpectedDataBytes()) {
    throw InternalError(fmt::format("DDS: {} bytes of texels, expected {}", t.data.size(), t.ExpectedDataBytes()));
  }
  std::string out;
  out.reserve(kHeaderBytes + t.data.size());
  PutU32(out, kMagic);
  // DDS_HEADER
  PutU32(out, 124);                         // dwSize
  PutU32(out, FlagsOf(t));                  // dwFlags
  PutU32(out, t.height);                    // dwHeight
  PutU32(out, t.width);                     // dwWidth
  PutU32(out, t.width * t.bytes_per_texel); // dwPitchOrLinearSize: bytes per row
  PutU32(out, t.Is3D() ? t.depth : 0);      // dwDepth
  PutU32(out, 1);                           // dwMipMapCount
  for (int i = 0; i < 11; ++i) PutU32(out, 0);  // dwReserved1
  // DDS_PIXELFORMAT
  PutU32(out, 32);
  PutU32(out, kDdpfFourCc);
  PutU32(out, kFourCcDx10);
  for (int i = 0; i < 5; ++i) PutU32(out, 0);  // dwRGBBitCount, R/G/B/A masks
  PutU32(out, kDdsCapsTexture);                 // dwCaps
  PutU32(out, t.Is3D() ? kDdsCaps2Volume : 0);  // dwCaps2
  PutU32(out, 0);                               // dwCaps3
  PutU32(out, 0);                               // dwCaps4
  PutU32(out, 0);                               // dwReserved2
  // DDS_HEADER_DXT10
  PutU32(out, t.dxgi_format);
  PutU32(out, t.Is3D() ? kDimensionTexture3D : kDimensionTexture2D);
  PutU32(out, 0);  // miscFlag
  PutU32(out, t.array_size);
  PutU32(out, 0);  // miscFlags2: DDS_ALPHA_MODE_UNKNOWN
  SKYBAKE_CHECK_EQ(out.size(), kHeaderBytes);
  out += t.data;
  return out;
}

bool WriteDds(const std::filesystem::path& path, const Texture& texture) {
  return WriteFileIfChanged(path, EncodeDds(texture));
}

Texture DecodeDds(const std::string& b, const std::string& name) {
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, "DDS: " + msg); };
  if (b.size() < kHeaderBytes) fail(fmt::format("{} bytes, shorter than the 148-byte DX10 header", b.size()));
  auto field = [&](size_t pos, uint32_t expect, const char* what) {
    const uint32_t v = GetU32(b, pos);
    if (v != expect) fail(fmt::format("{} is 0x{:x}, expected 0x{:x}", what, v, expect));
  };
  field(0, kMagic, "the magic number");
  field(4, 124, "DDS_HEADER.dwSize");
  field(76, 32, "DDS_PIXELFORMAT.dwSize");
  field(80, kDdpfFourCc, "DDS_PIXELFORMAT.dwFlags");
  field(84, kFourCcDx10, "DDS_PIXELFORMAT.dwFourCC");
  Texture t;
  t.dxgi_format = GetU32(b, 128);
  if (t.dxgi_format != kDxgiFormatR11G11B10Float) fail(fmt::format("dxgiFormat {} is not R11G11B10_FLOAT (26)", t.dxgi_format));
  t.bytes_per_texel = 4;
  t.height = GetU32(b, 12);
  t.width = GetU32(b, 16);
  const uint32_t dim = GetU32(b, 132);
  if (dim != kDimensionTexture2D && dim != kDimensionTexture3D) fail(fmt::format("resourceDimension {} is not 3 or 4", dim));
  t.depth = dim == kDimensionTexture3D ? GetU32(b, 24) : 0;
  t.array_size = GetU32(b, 140);
  if (t.width == 0 || t.height == 0 || t.array_size == 0 || (dim == kDimensionTexture3D && t.depth == 0)) fail("zero size");
  field(8, FlagsOf(t), "DDS_HEADER.dwFlags");
  field(20, t.width * 4, "DDS_HEADER.dwPitchOrLinearSize");
  field(28, 1, "DDS_HEADER.dwMipMapCount");
  for (size_t pos = 32; pos < 76; pos += 4) field(pos, 0, "DDS_HEADER.dwReserved1");
  for (size_t pos = 88; pos < 108; pos += 4) field(pos, 0, "DDS_PIXELFORMAT bit count/masks");
  for (size_t pos = 116; pos < 128; pos += 4) field(pos, 0, "DDS_HEADER.dwCaps3/dwCaps4/dwReserved2");
  field(108, kDdsCapsTexture, "DDS_HEADER.dwCaps");
  field(112, dim == kDimensionTexture3D ? kDdsCaps2Volume : 0, "DDS_HEADER.dwCaps2");
  field(136, 0, "DDS_HEADER_DXT10.miscFlag");
  if (dim == kDimensionTexture3D) field(140, 1, "DDS_HEADER_DXT10.arraySize");
  field(144, 0, "DDS_HEADER_DXT10.miscFlags2");
  if (dim == kDimensionTexture2D) field(24, 0, "DDS_HEADER.dwDepth");
  t.data = b.substr(kHeaderBytes);
  if (t.data.size() != t.ExpectedDataBytes()) {
    fail(fmt::format("{} bytes of texels, expected {}", t.data.size(), t.ExpectedDataBytes()));
  }
  return t;
}

}  // namespace skybake::dds
