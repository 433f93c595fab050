// exr_finite: counts the non-finite values (NaN, +-inf) of every channel of every part of EXR
// files; the check of bench/mutation_run.py that an exit 0 produced finite outputs.
//
//   bench_exr_finite FILE.exr...   one line per file: "<file>: <values> values, <bad> non-finite"
//                                  (and the channels holding them); exit 0 when every value is
//                                  finite, 1 when some are not, 2 when a file cannot be read.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "io/error.h"
#include "io/exr.h"

int main(int argc, char** argv) {
  int rc = 0;
  for (int i = 1; i < argc; ++i) {
    try {
      size_t values = 0, bad = 0;
      std::string where;
      for (const skybake::ExrPart& part : skybake::ReadExrParts(argv[i])) {
        const skybake::ExrImage& im = part.image;
        const size_t nc = im.channels.size();
        for (size_t c = 0; c < nc; ++c) {
          size_t channel_bad = 0;
          for (size_t k = c; k < im.pixels.size(); k += nc) channel_bad += std::isfinite(im.pixels[k]) ? 0 : 1;
          if (channel_bad > 0) where += " " + part.name + "." + im.channels[c];
          bad += channel_bad;
        }
        values += im.pixels.size();
      }
      std::printf("%s: %zu values, %zu non-finite%s\n", argv[i], values, bad, where.c_str());
      if (bad > 0 && rc == 0) rc = 1;
    } catch (const std::exception& e) {
      std::printf("%s: cannot read: %s\n", argv[i], e.what());
      rc = 2;
    }
  }
  return rc;
}
