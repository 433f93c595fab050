// Colour EXR images: the chromaticities attribute says what R, G, B are, consistently with the
// OCIO config, and survives a write/read round trip.
#include <gtest/gtest.h>

#include <ImfChromaticities.h>

#include "color/color.h"
#include "color/exr_color.h"
#include "io/exr.h"

using namespace skybake;

namespace {
const ColorConfig& Config() {
  static const ColorConfig c = ColorConfig::Load(std::string(SKYBAKE_SOURCE_DIR) + "/ocio/config.ocio");
  return c;
}
}  // namespace

// An EXR reader that applies OpenEXR's own RGBtoXYZ to our Rec.2020 chromaticities gets the
// same XYZ as OCIO's "Linear Rec.2020" -> "CIE-XYZ-D65" (to float precision of the attribute):
// file metadata and config agree.
TEST(ExrColor, Rec2020ChromaticitiesAgreeWithOcio) {
  const Imath::M44f m = Imf::RGBtoXYZ(Rec2020Chromaticities(), 1.0f);  // row vectors: xyz = rgb * m
  ColorProcessor p = Config().Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  for (int c = 0; c < 3; ++c) {
    std::array<float, 3> rgb{0, 0, 0};
    rgb[c] = 1.0f;
    std::array<float, 3> xyz = p.Apply(rgb);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m[c][k], xyz[k], 2e-6) << "primary " << c << " component " << k;
  }
  const Imath::M44f m709 = Imf::RGBtoXYZ(Rec709Chromaticities(), 1.0f);
  std::array<float, 3> g = Config().Converter(ocio_names::kLinearRec709, ocio_names::kCieXyzD65).Apply({0, 1, 0});
  EXPECT_NEAR(m709[1][1], g[1], 2e-6);  // Rec.709 green luminance 0.7152
}

// XYZ and Rec.2020 images written and read back keep pixels, chromaticities and the OCIO name;
// without skybake.colorspace the space is recognised from the chromaticities alone.
TEST(ExrColor, RoundTripAndRecognition) {
  std::vector<float> px{0.1f, 0.2f, 0.3f, 1000.0f, 2000.0f, 3000.0f};
  for (const char* space : {ocio_names::kCieXyzD65, ocio_names::kLinearRec2020, ocio_names::kLinearRec709}) {
    ExrImage img = MakeColorImage(2, 1, px, space);
    ExrImage back = DecodeExr(EncodeExr(img), "t.exr");
    EXPECT_EQ(InterleavedRgb(back, "t.exr"), px);  // the file holds B, G, R (EXR sorts channel names)
    ASSERT_TRUE(back.chromaticities.has_value());
    EXPECT_EQ(ColorSpaceOfImage(back, "t.exr"), space);
    back.strings.erase("skybake.colorspace");
    EXPECT_EQ(ColorSpaceOfImage(back, "t.exr"), space);
  }
  ExrImage xyz = DecodeExr(EncodeExr(MakeColorImage(2, 1, px, ocio_names::kCieXyzD65)), "t.exr");
  EXPECT_EQ(xyz.chromaticities->white, Imath::V2f(1.0f / 3.0f, 1.0f / 3.0f));  // XYZ convention, io/exr.h
  EXPECT_EQ(xyz.chromaticities->red, Imath::V2f(1.0f, 0.0f));
  ExrImage r2020 = DecodeExr(EncodeExr(MakeColorImage(2, 1, px, ocio_names::kLinearRec2020)), "t.exr");
  EXPECT_EQ(r2020.chromaticities->red, Imath::V2f(0.708f, 0.292f));   // ITU-R BT.2020
  EXPECT_EQ(r2020.chromaticities->white, Imath::V2f(0.3127f, 0.3290f));  // D65
}

TEST(ExrColor, RefusesSpacesAnExrCannotDescribe) {
  EXPECT_THROW(MakeColorImage(1, 1, {1, 1, 1}, ocio_names::kCie2006Xyz), InternalError);
  ExrImage img = MakeColorImage(1, 1, {1, 1, 1}, ocio_names::kLinearRec709);
  img.strings.erase("skybake.colorspace");
  img.chromaticities = Imf::Chromaticities(Imath::V2f(0.68f, 0.32f), Imath::V2f(0.265f, 0.69f), Imath::V2f(0.15f, 0.06f),
                                           Imath::V2f(0.3127f, 0.329f));  // Display P3
  try {
    ColorSpaceOfImage(img, "p3.exr");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "p3.exr: its chromaticities are none of CIE XYZ, Rec.2020 or Rec.709 (convert it with OCIO first)");
  }
}
