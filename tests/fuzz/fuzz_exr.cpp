// The EXR reader (io/exr.h) on arbitrary bytes: single- and multi-part decoding and the table
// view of every part (the reader of profiles.exr, Mie tables and renders).
#include "fuzz_common.h"
#include "io/exr.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = fuzz::Text(data, size);
  fuzz::Guarded([&] {
    for (const ExrPart& p : DecodeExrParts(bytes, "fuzz.exr")) {
      fuzz::Guarded([&] { (void)ImageToTable(p.image, "fuzz.exr"); });
    }
  });
  fuzz::Guarded([&] { (void)DecodeExr(bytes, "fuzz.exr"); });
  return 0;
}
