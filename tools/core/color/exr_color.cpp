#include "color/exr_color.h"

#include <cmath>

#include <fmt/format.h>

#include "color/color.h"
#include "color/primaries.h"
#include "io/error.h"

namespace skybake {

namespace {
Imf::Chromaticities FromPrimaries(const RgbPrimaries& p) {
  auto v = [](const Xy& c) { return Imath::V2f(static_cast<float>(c.x), static_cast<float>(c.y)); };
  return Imf::Chromaticities(v(p.red), v(p.green), v(p.blue), v(p.white));
}

bool Near(const Imath::V2f& a, const Imath::V2f& b) { return std::abs(a.x - b.x) < 1e-4f && std::abs(a.y - b.y) < 1e-4f; }
bool Same(const Imf::Chromaticities& a, const Imf::Chromaticities& b) {
  return Near(a.red, b.red) && Near(a.green, b.green) && Near(a.blue, b.blue) && Near(a.white, b.white);
}
}  // namespace

Imf::Chromaticities Rec2020Chromaticities() { return FromPrimaries(kRec2020Primaries); }
Imf::Chromaticities Rec709Chromaticities() { return FromPrimaries(kRec709Primaries); }

std::optional<Imf::Chromaticities> ChromaticitiesOf(std::string_view colorspace) {
  if (colorspace == ocio_names::kCieXyzD65) return XyzChromaticities();
  if (colorspace == ocio_names::kLinearRec2020) return Rec2020Chromaticities();
  if (colorspace == ocio_names::kLinearRec709) return Rec709Chromaticities();
  return std::nullopt;
}

ExrImage MakeColorImage(int width, int height, std::vector<float> rgb, std::string_view colorspace) {
  std::optional<Imf::Chromaticities> chroma = ChromaticitiesOf(colorspace);
  if (!chroma) {
    throw InternalError(fmt::format("MakeColorImage: '{}' cannot be described by EXR chromaticities; convert to {}, {} or {} first",
                                    colorspace, ocio_names::kCieXyzD65, ocio_names::kLinearRec2020, ocio_names::kLinearRec709));
  }
  SKYBAKE_CHECK(width > 0 && height > 0);
  SKYBAKE_CHECK_EQ(rgb.size(), static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  ExrImage image;
  image.Resize(width, height, {"R", "G", "B"});
  image.pixels = std::move(rgb);
  image.chromaticities = *chroma;
  image.strings["skybake.colorspace"] = std::string(colorspace);
  return image;
}

namespace {
void RequireRgb(const ExrImage& image, const FileLoc& where) {
  for (const char* c : {"R", "G", "B"}) {
    if (image.ChannelIndex(c) < 0) throw InputError(where, fmt::format("a colour image needs channels R, G, B; '{}' is missing", c));
  }
}
}  // namespace

std::vector<float> InterleavedRgb(const ExrImage& image, const std::string& display_name) {
  RequireRgb(image, FileLoc{display_name, 0});
  const int idx[3] = {image.ChannelIndex("R"), image.ChannelIndex("G"), image.ChannelIndex("B")};
  std::vector<float> out(static_cast<size_t>(image.width) * static_cast<size_t>(image.height) * 3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) out[(static_cast<size_t>(y) * image.width + x) * 3 + c] = image.At(x, y, idx[c]);
    }
  }
  return out;
}

std::string ColorSpaceOfImage(const ExrImage& image, const std::string& display_name) {
  const FileLoc where{display_name, 0};
  RequireRgb(image, where);
  auto it = image.strings.find("skybake.colorspace");
  if (it != image.strings.end()) {
    if (!ChromaticitiesOf(it->second)) {
      throw InputError(where, fmt::format("skybake.colorspace '{}' is not one of '{}', '{}', '{}'", it->second,
                                          ocio_names::kCieXyzD65, ocio_names::kLinearRec2020, ocio_names::kLinearRec709));
    }
    return it->second;
  }
  const Imf::Chromaticities c = image.chromaticities ? *image.chromaticities : Rec709Chromaticities();
  for (const char* name : {ocio_names::kCieXyzD65, ocio_names::kLinearRec2020, ocio_names::kLinearRec709}) {
    if (Same(c, *ChromaticitiesOf(name))) return name;
  }
  throw InputError(where, "its chromaticities are none of CIE XYZ, Rec.2020 or Rec.709 (convert it with OCIO first)");
}

}  // namespace skybake
