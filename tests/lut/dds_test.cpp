// DDS writer and reader (lut/dds.h): every header field of a volume and of a 2D array at its
// offset, against the values of Microsoft's DDS_HEADER / DDS_PIXELFORMAT / DDS_HEADER_DXT10
// documentation (learn.microsoft.com/windows/win32/direct3ddds, written out by hand below), the
// texel bytes after the 148-byte header, round trips, and rejection of malformed files.
#include <gtest/gtest.h>

#include <cstring>

#include "io/error.h"
#include "lut/dds.h"

using namespace skybake;
using namespace skybake::dds;

namespace {

uint32_t U32(const std::string& b, size_t pos) {
  uint32_t v;
  std::memcpy(&v, b.data() + pos, 4);
  return v;
}

Texture Make(uint32_t w, uint32_t h, uint32_t d, uint32_t layers) {
  Texture t;
  t.width = w;
  t.height = h;
  t.depth = d;
  t.array_size = layers;
  t.data.resize(t.ExpectedDataBytes());
  for (size_t i = 0; i < t.data.size(); ++i) t.data[i] = static_cast<char>((i * 29 + 3) & 0xFF);
  return t;
}

}  // namespace

TEST(Dds, VolumeHeaderFieldByField) {
  const Texture t = Make(32, 128, 64, 1);
  const std::string b = EncodeDds(t);
  ASSERT_EQ(b.size(), 148u + 32u * 128u * 64u * 4u);
  EXPECT_EQ(b.substr(0, 4), "DDS ");
  EXPECT_EQ(U32(b, 4), 124u);                                  // dwSize
  EXPECT_EQ(U32(b, 8), 0x1u | 0x2u | 0x4u | 0x8u | 0x1000u | 0x20000u | 0x800000u);  // CAPS HEIGHT WIDTH PITCH PIXELFORMAT MIPMAPCOUNT DEPTH
  EXPECT_EQ(U32(b, 12), 128u);                                 // dwHeight
  EXPECT_EQ(U32(b, 16), 32u);                                  // dwWidth
  EXPECT_EQ(U32(b, 20), 32u * 4u);                             // dwPitchOrLinearSize (bytes per row)
  EXPECT_EQ(U32(b, 24), 64u);                                  // dwDepth
  EXPECT_EQ(U32(b, 28), 1u);                                   // dwMipMapCount
  for (size_t p = 32; p < 76; p += 4) EXPECT_EQ(U32(b, p), 0u) << "dwReserved1 at " << p;
  EXPECT_EQ(U32(b, 76), 32u);                                  // ddspf.dwSize
  EXPECT_EQ(U32(b, 80), 0x4u);                                 // DDPF_FOURCC
  EXPECT_EQ(b.substr(84, 4), "DX10");                          // dwFourCC
  for (size_t p = 88; p < 108; p += 4) EXPECT_EQ(U32(b, p), 0u) << "bit count / masks at " << p;
  EXPECT_EQ(U32(b, 108), 0x1000u);                             // DDSCAPS_TEXTURE
  EXPECT_EQ(U32(b, 112), 0x200000u);                           // DDSCAPS2_VOLUME
  EXPECT_EQ(U32(b, 116), 0u);
  EXPECT_EQ(U32(b, 120), 0u);
  EXPECT_EQ(U32(b, 124), 0u);
  EXPECT_EQ(U32(b, 128), 26u);                                 // DXGI_FORMAT_R11G11B10_FLOAT
  EXPECT_EQ(U32(b, 132), 4u);                                  // DDS_DIMENSION_TEXTURE3D
  EXPECT_EQ(U32(b, 136), 0u);                                  // miscFlag
  EXPECT_EQ(U32(b, 140), 1u);                                  // arraySize: 1 for 3D
  EXPECT_EQ(U32(b, 144), 0u);                                  // miscFlags2: DDS_ALPHA_MODE_UNKNOWN
  EXPECT_EQ(b.substr(148), t.data);
  const Texture back = DecodeDds(b, "v.dds");
  EXPECT_EQ(back.width, 32u);
  EXPECT_EQ(back.height, 128u);
  EXPECT_EQ(back.depth, 64u);
  EXPECT_EQ(back.array_size, 1u);
  EXPECT_EQ(back.data, t.data);
}

TEST(Dds, ArrayAnd2dHeaders) {
  const Texture a = Make(16, 64, 0, 64);
  const std::string b = EncodeDds(a);
  EXPECT_EQ(U32(b, 8), 0x1u | 0x2u | 0x4u | 0x8u | 0x1000u | 0x20000u);  // no DDSD_DEPTH
  EXPECT_EQ(U32(b, 24), 0u);
  EXPECT_EQ(U32(b, 112), 0u);   // not a volume
  EXPECT_EQ(U32(b, 132), 3u);   // DDS_DIMENSION_TEXTURE2D
  EXPECT_EQ(U32(b, 140), 64u);  // arraySize
  EXPECT_EQ(DecodeDds(b, "a.dds").data, a.data);
  const Texture p = Make(181, 8, 0, 1);
  const std::string c = EncodeDds(p);
  EXPECT_EQ(U32(c, 140), 1u);
  EXPECT_EQ(U32(c, 20), 181u * 4u);
}

TEST(Dds, ReaderRejectsMalformedFiles) {
  const std::string good = EncodeDds(Make(4, 8, 2, 1));
  auto expect_bad = [&](size_t pos, uint32_t value, const std::string& word) {
    std::string b = good;
    std::memcpy(b.data() + pos, &value, 4);
    try {
      DecodeDds(b, "bad.dds");
      ADD_FAILURE() << "accepted a file with 0x" << std::hex << value << " at " << std::dec << pos;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  expect_bad(0, 0x12345678, "magic");
  expect_bad(4, 120, "dwSize");
  expect_bad(8, 0x1007, "dwFlags");
  expect_bad(20, 5, "dwPitchOrLinearSize");
  expect_bad(28, 2, "dwMipMapCount");
  expect_bad(84, 0x31545844, "dwFourCC");  // "DXT1"
  expect_bad(112, 0, "dwCaps2");
  expect_bad(128, 10, "dxgiFormat");
  expect_bad(132, 5, "resourceDimension");
  expect_bad(140, 2, "arraySize");
  EXPECT_THROW(DecodeDds(good.substr(0, 100), "short.dds"), InputError);
  EXPECT_THROW(DecodeDds(good.substr(0, good.size() - 4), "truncated.dds"), InputError);
  EXPECT_THROW(DecodeDds(good + "xxxx", "long.dds"), InputError);
}

TEST(Dds, WriterRejectsInconsistentTextures) {
  Texture t = Make(4, 4, 2, 1);
  t.array_size = 2;
  EXPECT_THROW(EncodeDds(t), InternalError);
  Texture u = Make(4, 4, 0, 1);
  u.data.pop_back();
  EXPECT_THROW(EncodeDds(u), InternalError);
  Texture z = Make(4, 4, 0, 1);
  z.width = 0;
  EXPECT_THROW(EncodeDds(z), InternalError);
}
