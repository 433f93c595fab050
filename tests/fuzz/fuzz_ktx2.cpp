// The KTX2 reader (lut/ktx2.h) on arbitrary bytes, and the texel decoder of what it accepts.
#include "fuzz_common.h"
#include "lut/ktx2.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Guarded([&] {
    const ktx2::Texture t = ktx2::DecodeKtx2(fuzz::Text(data, size), "fuzz.ktx2");
    // DecodeKtx2 reads any sized format; DecodeTexels covers skybake's float and UNORM ones (R11G11B10
    // texels are lut/r11g11b10.h's), and asking it for another is a caller's bug (InternalError).
    for (const ktx2::Format& f : {ktx2::R8Unorm(), ktx2::R8G8Unorm(), ktx2::R8G8B8A8Unorm(), ktx2::R16Sfloat(),
                                  ktx2::R16G16B16A16Sfloat(), ktx2::R32Sfloat(), ktx2::R32G32B32A32Sfloat()}) {
      if (t.format.vk_format == f.vk_format) (void)ktx2::DecodeTexels(t.format, t.data);
    }
  });
  return 0;
}
