#include "lut/inspection.h"

#include "color/color.h"
#include "color/exr_color.h"

namespace skybake::lut {

ExrImage PackedInspectionImage(int width, int height, const PackedTexture& t, const std::string& channels_description) {
  const ExrImage colour = MakeColorImage(width, height, t.decoded_rgb, ocio_names::kLinearRec2020);
  ExrImage img;
  img.Resize(width, height, {"R", "G", "B", "input_R", "input_G", "input_B", "clamp_flags"});
  const size_t n = static_cast<size_t>(width) * height;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      img.pixels[i * 7 + c] = t.decoded_rgb[i * 3 + c];
      img.pixels[i * 7 + 3 + c] = t.input_rgb[i * 3 + c];
    }
    img.pixels[i * 7 + 6] = t.clamp_flags[i];
  }
  img.chromaticities = colour.chromaticities;
  img.strings = colour.strings;
  img.strings["skybake.channels"] = channels_description;
  img.doubles["skybake.scale"] = t.scale;
  return img;
}

}  // namespace skybake::lut
