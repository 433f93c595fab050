// KTX2 writer and reader (lut/ktx2.h): header fields, DFD words, key/value order and padding,
// level alignment, round trips, strict rejection of malformed files, and the texel encoders
// (float -> half exhaustively against the decoder and Imath, float -> UNORM8).
//
// Expected values come from the KTX 2.0 specification (KhronosGroup/KTX-Specification
// ktxspec.adoc) and the Khronos Data Format Specification 1.3 basic descriptor block as written
// by KTX-Software lib/dfdutils (createdfd.c); the B10G11R11 DFD from lib/dfdutils
// vk2dfd.inl. They are written out by hand below, not computed by the code under test.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "io/error.h"
#include "io/fileio.h"
#include "lut/ktx2.h"

using namespace skybake;
using namespace skybake::ktx2;

namespace {

uint32_t U32(const std::string& b, size_t pos) {
  uint32_t v;
  std::memcpy(&v, b.data() + pos, 4);
  return v;
}
uint64_t U64(const std::string& b, size_t pos) {
  uint64_t v;
  std::memcpy(&v, b.data() + pos, 8);
  return v;
}

Texture Make(Format f, uint32_t w, uint32_t h, uint32_t d, uint32_t layers) {
  Texture t;
  t.format = std::move(f);
  t.width = w;
  t.height = h;
  t.depth = d;
  t.layers = layers;
  t.writer = "skybake test 0.0.0";
  t.data.resize(t.ExpectedDataBytes());
  for (size_t i = 0; i < t.data.size(); ++i) t.data[i] = static_cast<char>((i * 37 + 11) & 0xFF);
  return t;
}

// The key/value pairs of an encoded file, in file order, checking lengths and zero padding.
std::vector<std::pair<std::string, std::string>> KeyValues(const std::string& b) {
  const uint32_t off = U32(b, 56), len = U32(b, 60);
  std::vector<std::pair<std::string, std::string>> kv;
  size_t q = off;
  while (q < off + len) {
    EXPECT_EQ(q % 4, 0u) << "keyAndValueByteLength must be 4-byte aligned";
    const uint32_t n = U32(b, q);
    q += 4;
    const std::string pair = b.substr(q, n);
    const size_t nul = pair.find('\0');
    kv.emplace_back(pair.substr(0, nul), pair.substr(nul + 1));
    q += n;
    while (q % 4) {
      EXPECT_EQ(b[q], '\0') << "valuePadding must be zeros";
      ++q;
    }
  }
  EXPECT_EQ(q, off + len) << "kvdByteLength must cover the pairs and their padding exactly";
  return kv;
}

}  // namespace

// ---------------------------------------------------------------------------- header and index

TEST(Ktx2, HeaderFieldsOfA3dR16Volume) {
  // A 5x3x2 R16_SFLOAT volume: odd sizes so that nothing is aligned by accident.
  Texture t = Make(R16Sfloat(), 5, 3, 2, 0);
  const std::string b = EncodeKtx2(t);
  const unsigned char id[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
  EXPECT_EQ(std::memcmp(b.data(), id, 12), 0);
  EXPECT_EQ(U32(b, 12), 76u);  // VK_FORMAT_R16_SFLOAT
  EXPECT_EQ(U32(b, 16), 2u);   // typeSize: bytes of one 16-bit component
  EXPECT_EQ(U32(b, 20), 5u);
  EXPECT_EQ(U32(b, 24), 3u);
  EXPECT_EQ(U32(b, 28), 2u);   // pixelDepth > 0: a 3D texture
  EXPECT_EQ(U32(b, 32), 0u);   // layerCount 0: not an array
  EXPECT_EQ(U32(b, 36), 1u);   // faceCount
  EXPECT_EQ(U32(b, 40), 1u);   // levelCount: one level
  EXPECT_EQ(U32(b, 44), 0u);   // no supercompression
  // Index: header (48) + index (32) + one level entry (24) = 104.
  EXPECT_EQ(U32(b, 48), 104u);       // dfdByteOffset
  EXPECT_EQ(U32(b, 52), 44u);        // dfdByteLength: 4 + 24 + 16 x 1 sample
  EXPECT_EQ(U32(b, 56), 148u);       // kvdByteOffset = 104 + 44
  EXPECT_EQ(U64(b, 64), 0u);         // sgdByteOffset
  EXPECT_EQ(U64(b, 72), 0u);         // sgdByteLength
  const uint64_t level_offset = U64(b, 80);
  EXPECT_EQ(level_offset % 4, 0u);   // lcm(texel block size 2, 4) = 4
  EXPECT_GE(level_offset, 148u + U32(b, 60));
  EXPECT_LT(level_offset, 148u + U32(b, 60) + 4u);
  EXPECT_EQ(U64(b, 88), 5u * 3u * 2u * 2u);  // byteLength
  EXPECT_EQ(U64(b, 96), U64(b, 88));         // uncompressedByteLength
  EXPECT_EQ(b.size(), level_offset + 60u);
  EXPECT_EQ(b.substr(level_offset), t.data);
}

TEST(Ktx2, ArrayAnd2dTypesInTheHeader) {
  Texture a = Make(R8G8Unorm(), 4, 3, 0, 5);  // 2D array of 5 layers
  std::string b = EncodeKtx2(a);
  EXPECT_EQ(U32(b, 12), 16u);  // VK_FORMAT_R8G8_UNORM
  EXPECT_EQ(U32(b, 16), 1u);
  EXPECT_EQ(U32(b, 28), 0u);
  EXPECT_EQ(U32(b, 32), 5u);
  EXPECT_EQ(U64(b, 88), 4u * 3u * 5u * 2u);
  Texture p = Make(R8G8B8A8Unorm(), 7, 2, 0, 0);  // plain 2D
  b = EncodeKtx2(p);
  EXPECT_EQ(U32(b, 12), 37u);  // VK_FORMAT_R8G8B8A8_UNORM
  EXPECT_EQ(U32(b, 16), 1u);   // typeSize 1 for 8-bit components
  EXPECT_EQ(U32(b, 28), 0u);
  EXPECT_EQ(U32(b, 32), 0u);
}

// ---------------------------------------------------------------------------- DFDs

TEST(Ktx2, DfdOfR8Unorm) {
  const std::string d = EncodeDfd(R8Unorm().dfd);
  ASSERT_EQ(d.size(), 44u);
  EXPECT_EQ(U32(d, 0), 44u);                       // dfdTotalSize
  EXPECT_EQ(U32(d, 4), 0u);                        // vendorId 0 (Khronos), descriptorType 0 (basic)
  EXPECT_EQ(U32(d, 8), 2u | (40u << 16));          // versionNumber 2 (KDF 1.3), blockSize 24 + 16
  EXPECT_EQ(U32(d, 12), 1u | (1u << 8) | (1u << 16));  // RGBSDA, BT709, LINEAR, straight alpha
  EXPECT_EQ(U32(d, 16), 0u);                       // texelBlockDimension 1x1x1x1
  EXPECT_EQ(U32(d, 20), 1u);                       // bytesPlane0 = 1
  EXPECT_EQ(U32(d, 24), 0u);
  EXPECT_EQ(U32(d, 28), 0u | (7u << 16) | (0u << 24));  // bitOffset 0, bitLength 8 - 1, RED
  EXPECT_EQ(U32(d, 32), 0u);                       // samplePosition
  EXPECT_EQ(U32(d, 36), 0u);                       // sampleLower
  EXPECT_EQ(U32(d, 40), 255u);                     // sampleUpper = 2^8 - 1
}

TEST(Ktx2, DfdOfR16Sfloat) {
  const std::string d = EncodeDfd(R16Sfloat().dfd);
  ASSERT_EQ(d.size(), 44u);
  EXPECT_EQ(U32(d, 20), 2u);                                  // bytesPlane0 = 2
  EXPECT_EQ(U32(d, 28), 0u | (15u << 16) | (0xC0u << 24));    // 16 bits, RED | FLOAT | SIGNED
  EXPECT_EQ(U32(d, 36), 0xBF800000u);                         // sampleLower = -1.0f
  EXPECT_EQ(U32(d, 40), 0x3F800000u);                         // sampleUpper = 1.0f
}

TEST(Ktx2, DfdOfR8G8B8A8Unorm) {
  const std::string d = EncodeDfd(R8G8B8A8Unorm().dfd);
  ASSERT_EQ(d.size(), 92u);                        // 4 + 24 + 16 x 4
  EXPECT_EQ(U32(d, 8), 2u | (88u << 16));
  EXPECT_EQ(U32(d, 20), 4u);                       // bytesPlane0 = 4
  const uint32_t ids[4] = {0, 1, 2, 15};           // R, G, B, A (alpha is channel 15)
  for (int c = 0; c < 4; ++c) {
    const size_t p = 28 + 16 * c;
    EXPECT_EQ(U32(d, p), (8u * c) | (7u << 16) | (ids[c] << 24)) << "sample " << c;
    EXPECT_EQ(U32(d, p + 8), 0u);
    EXPECT_EQ(U32(d, p + 12), 255u);
  }
}

TEST(Ktx2, DfdOfB10G11R11UfloatPack32MatchesTheNotes) {
  Format f = B10G11R11UfloatPack32();
  EXPECT_EQ(static_cast<uint32_t>(f.vk_format), 122u);
  EXPECT_EQ(f.type_size, 4u);
  const std::string d = EncodeDfd(f.dfd);
  ASSERT_EQ(d.size(), 76u);                        // dfdTotalSize 76
  EXPECT_EQ(U32(d, 8), 2u | (72u << 16));          // blockSize 24 + 16 x 3
  EXPECT_EQ(U32(d, 20), 4u);                       // bytesPlane0 = 4
  // {bitOffset, bitLength - 1, channelType}: R 0/10/0x80, G 11/10/0x81, B 22/9/0x82.
  const uint32_t expect[3][3] = {{0, 10, 0x80}, {11, 10, 0x81}, {22, 9, 0x82}};
  for (int c = 0; c < 3; ++c) {
    const size_t p = 28 + 16 * c;
    EXPECT_EQ(U32(d, p), expect[c][0] | (expect[c][1] << 16) | (expect[c][2] << 24)) << "sample " << c;
    EXPECT_EQ(U32(d, p + 8), 0u);
    EXPECT_EQ(U32(d, p + 12), 0x3F800000u);
  }
}

TEST(Ktx2, DfdRoundTrip) {
  for (const Format& f : {R8Unorm(), R8G8Unorm(), R8G8B8A8Unorm(), R16Sfloat(), R16G16B16A16Sfloat(), R32Sfloat(),
                          R32G32B32A32Sfloat(), B10G11R11UfloatPack32()}) {
    EXPECT_EQ(DecodeDfd(EncodeDfd(f.dfd), "mem"), f.dfd) << f.name;
  }
}

// ---------------------------------------------------------------------------- key/value data

TEST(Ktx2, KeyValueDataIsSortedByCodePointWithKtxWriter) {
  Texture t = Make(R8Unorm(), 4, 4, 0, 0);
  SetString(t, "zeta", "last");
  SetString(t, "alpha", "a");
  SetString(t, "skybake.tool", "noise-gen");
  SetString(t, "KTXorientation", "rd");
  t.metadata["binary"] = std::string("\x01\x00\x02", 3);  // values may be arbitrary bytes
  const std::string b = EncodeKtx2(t);
  const auto kv = KeyValues(b);
  std::vector<std::string> keys;
  for (const auto& [k, v] : kv) keys.push_back(k);
  // Upper case sorts before lower case (U+004B 'K' < U+0061 'a').
  EXPECT_EQ(keys, (std::vector<std::string>{"KTXorientation", "KTXwriter", "alpha", "binary", "skybake.tool", "zeta"}));
  EXPECT_EQ(kv[1].second, std::string("skybake test 0.0.0\0", 19));  // NUL-terminated UTF-8
  EXPECT_EQ(kv[3].second, std::string("\x01\x00\x02", 3));
  // The DFD ends where the key/value data begins (ktxspec dfdTotalSize rule).
  EXPECT_EQ(U32(b, 48) + U32(b, 52), U32(b, 56));
}

TEST(Ktx2, LevelIsAlignedForEveryKeyLength) {
  // Texel blocks of 1, 2, 4 and 8 bytes; KV lengths 0..11 mod 4 and 8: the level must start on
  // lcm(block, 4) with zero mipPadding, and read back unchanged.
  for (const Format& f : {R8Unorm(), R16Sfloat(), R8G8B8A8Unorm(), R16G16B16A16Sfloat()}) {
    for (int n = 0; n < 12; ++n) {
      Texture t = Make(f, 3, 2, 0, 0);
      SetString(t, "k", std::string(n, 'x'));
      const std::string b = EncodeKtx2(t);
      const size_t align = f.texel_block_bytes == 8 ? 8 : 4;
      EXPECT_EQ(U64(b, 80) % align, 0u) << f.name << " n=" << n;
      Texture back = DecodeKtx2(b, "mem");
      EXPECT_EQ(back.data, t.data);
      EXPECT_EQ(back.GetString("k"), std::string(n, 'x'));
    }
  }
}

TEST(Ktx2, RoundTripThroughOwnReader) {
  Texture t = Make(R8G8B8A8Unorm(), 6, 5, 0, 3);
  SetString(t, "skybake.parameters", "a: 1\nb: [2, 3]\n");
  Texture back = DecodeKtx2(EncodeKtx2(t), "mem.ktx2");
  EXPECT_EQ(back.format.name, "R8G8B8A8_UNORM");
  EXPECT_EQ(back.width, 6u);
  EXPECT_EQ(back.height, 5u);
  EXPECT_EQ(back.depth, 0u);
  EXPECT_EQ(back.layers, 3u);
  EXPECT_EQ(back.writer, "skybake test 0.0.0");
  EXPECT_EQ(back.metadata, t.metadata);
  EXPECT_EQ(back.data, t.data);
  EXPECT_EQ(EncodeKtx2(back), EncodeKtx2(t)) << "decode/encode must be the identity";
}

// ---------------------------------------------------------------------------- strictness

namespace {
std::string DecodeError(const std::string& bytes) {
  try {
    DecodeKtx2(bytes, "bad.ktx2");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Ktx2, ReaderRejectsMalformedFiles) {
  Texture t = Make(R16Sfloat(), 4, 4, 4, 0);
  SetString(t, "b", "2");
  SetString(t, "a", "1");
  const std::string good = EncodeKtx2(t);
  ASSERT_EQ(DecodeError(good), "");

  std::string b = good;
  b[0] = 'X';
  EXPECT_EQ(DecodeError(b), "bad.ktx2: KTX2: missing the KTX 2.0 identifier");

  b = good;  // rename key "a" (it follows KTXwriter) to "c", which sorts after the next key "b"
  {
    const size_t a = good.find(std::string("a\0" "1", 3), U32(good, 56));
    ASSERT_NE(a, std::string::npos);
    b[a] = 'c';
  }
  EXPECT_EQ(DecodeError(b), "bad.ktx2: KTX2: keys are not sorted (or repeat): 'c' before 'b'");

  b = good;
  b.push_back('\0');
  EXPECT_EQ(DecodeError(b), "bad.ktx2: KTX2: the file has " + std::to_string(good.size() + 1) + " bytes; the level ends at " +
                                std::to_string(good.size()));

  b = good;  // claim R8_UNORM with a R16 DFD
  b[12] = 9;
  EXPECT_EQ(DecodeError(b), "bad.ktx2: KTX2: typeSize 2 does not match R8_UNORM (expected 1)");

  b = good;  // a non-zero valuePadding byte
  {
    // "a\0" "1\0" and "b\0" "2\0" need no padding; the KTXwriter pair (10 + 19 bytes) does.
    const size_t kvd = U32(good, 56);
    size_t q = kvd;
    for (int i = 0; i < 3; ++i) {  // a, b, KTXwriter - find the pair with padding
      const uint32_t n = U32(good, q);
      q += 4 + n;
      if (n % 4 != 0) break;
    }
    ASSERT_NE(q % 4, 0u);
    b[q] = 1;
  }
  EXPECT_EQ(DecodeError(b), "bad.ktx2: KTX2: valuePadding must be zero bytes");

  b = good;  // level length (and uncompressed length) one texel short
  b[88] = static_cast<char>(b[88] - 2);
  b[96] = static_cast<char>(b[96] - 2);
  EXPECT_NE(DecodeError(b).find("level 0 holds 126 bytes"), std::string::npos) << DecodeError(b);

  b = good;  // a broken sample upper bound in the DFD
  b[104 + 43] = 0;  // sampleUpper 0x3F800000 -> 0x00800000
  EXPECT_EQ(DecodeError(b), "bad.ktx2: KTX2: the DFD does not describe R16_SFLOAT");

  EXPECT_EQ(DecodeError(good.substr(0, 50)), "bad.ktx2: KTX2: file too short for a KTX2 header");
}

TEST(Ktx2, WriterRejectsInconsistentTextures) {
  Texture t = Make(R8Unorm(), 4, 4, 0, 0);
  t.data.pop_back();
  EXPECT_THROW(EncodeKtx2(t), InternalError);
  t = Make(R8Unorm(), 4, 4, 0, 0);
  SetString(t, "KTXfancy", "x");  // reserved prefix, not a predefined key
  EXPECT_THROW(EncodeKtx2(t), InternalError);
  t = Make(R8Unorm(), 4, 0, 2, 0);  // depth without height is no texture type
  t.data.resize(t.ExpectedDataBytes());
  EXPECT_THROW(EncodeKtx2(t), InternalError);
}

// ---------------------------------------------------------------------------- half floats

TEST(Half, SpecialValues) {
  EXPECT_EQ(FloatToHalf(0.0f), 0x0000);
  EXPECT_EQ(FloatToHalf(-0.0f), 0x8000);
  EXPECT_EQ(FloatToHalf(1.0f), 0x3C00);
  EXPECT_EQ(FloatToHalf(-2.0f), 0xC000);
  EXPECT_EQ(FloatToHalf(65504.0f), 0x7BFF);                    // largest finite half
  EXPECT_EQ(FloatToHalf(65519.99f), 0x7BFF);
  EXPECT_EQ(FloatToHalf(65520.0f), 0x7C00);                    // tie -> even -> infinity
  EXPECT_EQ(FloatToHalf(std::numeric_limits<float>::infinity()), 0x7C00);
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);       // smallest subnormal
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25)), 0x0000);       // tie between 0 and 2^-24 -> 0
  EXPECT_EQ(FloatToHalf(std::ldexp(1.5f, -24)), 0x0002);       // tie between 1 and 2 -> 2
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -14)), 0x0400);       // smallest normal
  EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3C00);  // tie -> even mantissa 0
  EXPECT_EQ(FloatToHalf(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3C02);  // tie -> even mantissa 2
  const uint16_t nan = FloatToHalf(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(nan & 0x7C00, 0x7C00);
  EXPECT_NE(nan & 0x03FF, 0);
  EXPECT_TRUE(std::isnan(HalfToFloat(nan)));
}

TEST(Half, DecoderIsExactForAllHalves) {
  // Every binary16 value: ours against Imath's decoder (independent), and the definition
  // (-1)^s 2^(e-15) (1 + m/1024), subnormals 2^-14 m/1024.
  for (uint32_t h = 0; h < 65536; ++h) {
    const float ours = HalfToFloat(static_cast<uint16_t>(h));
    Imath::half ih;
    ih.setBits(static_cast<uint16_t>(h));
    const float imath = static_cast<float>(ih);
    if (std::isnan(imath)) {
      EXPECT_TRUE(std::isnan(ours)) << h;
      continue;
    }
    ASSERT_EQ(std::bit_cast<uint32_t>(ours), std::bit_cast<uint32_t>(imath)) << "half 0x" << std::hex << h;
    const int e = (h >> 10) & 31, m = h & 1023;
    if (e != 31) {
      const double def = (h & 0x8000 ? -1.0 : 1.0) * (e == 0 ? std::ldexp(m, -24) : std::ldexp(1024 + m, e - 25));
      ASSERT_EQ(static_cast<double>(ours), def) << h;
    }
  }
}

TEST(Half, EncoderRoundsToNearestEvenForEveryFloatThatMatters) {
  // Exhaustive over every float of magnitude in [2^-28, 2^17) - all the floats whose half is
  // neither a certain zero nor a certain infinity (738 million, both signs): the encoded half
  // must be the nearest half (infinity standing for 2^16, IEEE overflow), a tie must pick the even
  // mantissa, and Imath::half (round-to-nearest-even, Imath 3.1 half.h) must agree.
  std::vector<double> value(0x7C01);
  for (uint32_t h = 0; h < 0x7C00; ++h) value[h] = static_cast<double>(HalfToFloat(static_cast<uint16_t>(h)));
  value[0x7C00] = 65536.0;
  std::atomic<uint64_t> failures{0};
  std::atomic<uint32_t> first_bad{0};
  const uint32_t lo = 0x31800000u, hi = 0x48000000u;  // 2^-28 .. 2^17
  tbb::parallel_for(tbb::blocked_range<uint32_t>(lo, hi, 1u << 16), [&](const tbb::blocked_range<uint32_t>& r) {
    uint64_t bad = 0;
    for (uint32_t bits = r.begin(); bits != r.end(); ++bits) {
      for (uint32_t sign : {0u, 0x80000000u}) {
        const float f = std::bit_cast<float>(bits | sign);
        const uint16_t h = FloatToHalf(f);
        const uint16_t hm = h & 0x7FFF;
        bool ok = ((h & 0x8000) != 0) == (sign != 0) && hm <= 0x7C00;
        if (ok) {
          const double x = std::fabs(static_cast<double>(f));
          const double d = std::fabs(x - value[hm]);
          if (hm > 0) {
            const double dl = std::fabs(x - value[hm - 1]);
            ok = ok && (d < dl || (d == dl && (hm & 1) == 0));
          }
          if (hm < 0x7C00) {
            const double du = std::fabs(x - value[hm + 1]);
            ok = ok && (d < du || (d == du && (hm & 1) == 0));
          }
          ok = ok && Imath::half(f).bits() == h;
        }
        if (!ok) {
          ++bad;
          first_bad.store(bits | sign);
        }
      }
    }
    failures += bad;
  });
  EXPECT_EQ(failures.load(), 0u) << "e.g. float bits 0x" << std::hex << first_bad.load();
  // Outside that range: zeros and infinities (every exponent, a spread of mantissas).
  for (uint32_t bits = 0; bits < lo; bits += 4093) {
    EXPECT_EQ(FloatToHalf(std::bit_cast<float>(bits)), 0x0000) << bits;
    EXPECT_EQ(FloatToHalf(std::bit_cast<float>(bits | 0x80000000u)), 0x8000) << bits;
  }
  for (uint32_t bits = hi; bits <= 0x7F800000u; bits += 4093) {
    EXPECT_EQ(FloatToHalf(std::bit_cast<float>(bits)), 0x7C00) << bits;
  }
  // Every NaN stays a NaN with its sign.
  for (uint32_t bits = 0x7F800001u; bits <= 0x7FFFFFFFu; bits += 7) {
    const uint16_t h = FloatToHalf(std::bit_cast<float>(bits | 0x80000000u));
    ASSERT_TRUE((h & 0x7C00) == 0x7C00 && (h & 0x3FF) != 0 && (h & 0x8000)) << bits;
  }
}

TEST(Unorm8, RoundsToNearestAndClamps) {
  EXPECT_EQ(FloatToUnorm8(0.0f), 0);
  EXPECT_EQ(FloatToUnorm8(1.0f), 255);
  EXPECT_EQ(FloatToUnorm8(-0.5f), 0);
  EXPECT_EQ(FloatToUnorm8(7.0f), 255);
  EXPECT_EQ(FloatToUnorm8(std::numeric_limits<float>::quiet_NaN()), 0);
  for (int c = 0; c < 256; ++c) {
    EXPECT_EQ(FloatToUnorm8(Unorm8ToFloat(static_cast<uint8_t>(c))), c);  // codes round-trip
    // Just inside either side of the decision boundary (c + 0.5)/255.
    if (c < 255) {
      const double mid = (c + 0.5) / 255.0;
      EXPECT_EQ(FloatToUnorm8(static_cast<float>(mid - 1e-6)), c);
      EXPECT_EQ(FloatToUnorm8(static_cast<float>(mid + 1e-6)), c + 1);
    }
  }
}

TEST(Texels, EncodeDecodeRoundTripsPerFormat) {
  const std::vector<float> v = {0.0f, 0.25f, -0.5f, 1.0f, 0.1f, 1e-3f, 3.0f, -2.0f};
  // UNORM8 clamps and rounds to 1/255 steps; half keeps 11 significant bits; float32 is exact.
  const std::vector<float> u8 = DecodeTexels(R8G8B8A8Unorm(), EncodeTexels(R8G8B8A8Unorm(), v));
  const std::vector<float> f16 = DecodeTexels(R16Sfloat(), EncodeTexels(R16Sfloat(), v));
  const std::vector<float> f32 = DecodeTexels(R32Sfloat(), EncodeTexels(R32Sfloat(), v));
  EXPECT_EQ(DecodeTexels(R32G32B32A32Sfloat(), EncodeTexels(R32G32B32A32Sfloat(), v)), v);  // fog-fit's parameter texture
  EXPECT_EQ(R32G32B32A32Sfloat().texel_block_bytes, 16u);
  ASSERT_EQ(u8.size(), v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    EXPECT_NEAR(u8[i], std::clamp(v[i], 0.0f, 1.0f), 0.5f / 255.0f + 1e-7f) << i;
    EXPECT_NEAR(f16[i], v[i], std::fabs(v[i]) * std::ldexp(1.0f, -11) + std::ldexp(1.0f, -25)) << i;
    EXPECT_EQ(f32[i], v[i]);
  }
  // Little-endian byte order of a half: 1.0 = 0x3C00 -> bytes 00 3C.
  EXPECT_EQ(EncodeTexels(R16Sfloat(), {1.0f}), std::string("\x00\x3c", 2));
  EXPECT_THROW(EncodeTexels(B10G11R11UfloatPack32(), {0.0f, 0.0f, 0.0f}), InternalError);
}

// Found by tests/fuzz/fuzz_ktx2.cpp: a header whose level 0 starts past the end of a
// truncated file was read beyond the buffer (ASan: heap-buffer-overflow) while checking
// mipPadding; it is bad input.
TEST(Ktx2, FileEndingBeforeItsLevelIsBadInput) {
  const std::string bytes =
      ReadFileBytes(std::filesystem::path(SKYBAKE_SOURCE_DIR) / "tests/fuzz/regressions/ktx2/ends_before_level0.ktx2");
  EXPECT_THROW(DecodeKtx2(bytes, "ends_before_level0.ktx2"), InputError);
}
