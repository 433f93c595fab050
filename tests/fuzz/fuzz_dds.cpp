// The DDS reader (lut/dds.h) on arbitrary bytes.
#include "fuzz_common.h"
#include "lut/dds.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Guarded([&] { (void)dds::DecodeDds(fuzz::Text(data, size), "fuzz.dds"); });
  return 0;
}
