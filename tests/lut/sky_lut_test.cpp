// lut-pack's packing statistics (lut/sky_lut.h PackRgb, AutomaticScale) on texels whose fate is
// known: values above the largest finite value clamp and are counted, negative Rec.2020 components
// clamp to 0 and are counted with their size relative to Y, denormal components are counted and
// kept out of the error distribution, and the luminance error of in-range texels is what the
// format's rounding gives (at most 2^-7 relative for grey, whose R = G = B).
#include <gtest/gtest.h>

#include <cmath>

#include "color/color.h"
#include "lut/r11g11b10.h"
#include "lut/sky_lut.h"

using namespace skybake;
using namespace skybake::lut;

namespace {
const ColorProcessor& ToXyz() {
  static const ColorConfig config = ColorConfig::Load();
  static const ColorProcessor p = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  return p;
}
}  // namespace

TEST(PackRgb, CountsClampsNegativesAndDenormals) {
  // 2 x 2 x 1: a grey in range, one above the largest value, one with a negative blue, one dim.
  const std::vector<float> rgb = {1024.0f, 1024.0f, 1024.0f,   // in range, exact in every channel
                                  70000.0f, 100.0f, 100.0f,    // R above 65024
                                  500.0f, 400.0f, -20.0f,      // B outside Rec.2020
                                  3e-5f, 3e-5f, 3e-5f};        // denormal (< 2^-14)
  const PackedTexture t = PackRgb(2, 2, 1, rgb, 1.0, ToXyz());
  EXPECT_EQ(t.bytes.size(), 16u);
  EXPECT_EQ(t.stats.texels, 4u);
  EXPECT_EQ(t.stats.clamped_high, 1u);
  EXPECT_EQ(t.stats.max_value, 70000.0);
  EXPECT_EQ(t.stats.negative_texels, 1u);
  EXPECT_GT(t.stats.worst_negative_fraction, 0.0);
  EXPECT_EQ(t.stats.denormal_texels, 1u);
  EXPECT_EQ(t.stats.measured, 1u);  // only the first texel enters the error distribution
  EXPECT_EQ(t.clamp_flags, (std::vector<uint8_t>{0, 1, 2, 4}));
  EXPECT_EQ(t.decoded_rgb[3], 65024.0f);
  EXPECT_EQ(t.decoded_rgb[8], 0.0f);
  // 1024 = 2^10 is a code of both channel kinds: no error for the measured texel.
  EXPECT_EQ(t.stats.y_rel_max, 0.0);
}

TEST(PackRgb, LuminanceErrorOfGreyIsTheRoundingOfItsValue) {
  // Greys 1 + k/1000 x 2^e: Y error = the 6-bit rounding error of the value (R = G = B, and B's
  // 5-bit mantissa enters Y with Rec.2020's weight 0.0593 only), so at most 2^-7 (1 + 0.0593).
  std::vector<float> rgb;
  for (int k = 0; k < 1000; ++k) {
    const float v = static_cast<float>(std::ldexp(1.0 + k / 1000.0, k % 20 - 5));
    rgb.insert(rgb.end(), {v, v, v});
  }
  const PackedTexture t = PackRgb(1000, 1, 1, rgb, 1.0, ToXyz());
  EXPECT_EQ(t.stats.measured, 1000u);
  EXPECT_LE(t.stats.y_rel_max, std::ldexp(1.0, -7) * (1 + 0.0593) + 1e-6);
  EXPECT_GT(t.stats.y_rel_max, 0.5 * std::ldexp(1.0, -7));
  EXPECT_LE(t.stats.channel_rel_max[0], std::ldexp(1.0, -7));
  EXPECT_LE(t.stats.channel_rel_max[2], std::ldexp(1.0, -6));
  EXPECT_LE(t.stats.y_rel_percentiles[0], t.stats.y_rel_percentiles[4]);
  EXPECT_EQ(t.stats.y_rel_percentiles[4], t.stats.y_rel_max);
  size_t h = 0;
  for (size_t n : t.stats.y_rel_histogram) h += n;
  EXPECT_EQ(h, 1000u);
}

TEST(PackRgb, ScaleIsAppliedAndUndone) {
  const std::vector<float> rgb = {200000.0f, 150000.0f, 100000.0f, 1.0f, 2.0f, 3.0f};
  const double s = AutomaticScale(rgb);
  EXPECT_EQ(s, 0.25);  // 200000 / 4 = 50000 <= 64512 < 200000 / 2
  const PackedTexture t = PackRgb(2, 1, 1, rgb, s, ToXyz());
  EXPECT_EQ(t.stats.clamped_high, 0u);
  for (size_t i = 0; i < rgb.size(); ++i) EXPECT_NEAR(t.decoded_rgb[i], rgb[i], rgb[i] * std::ldexp(1.0, -6));
  EXPECT_EQ(AutomaticScale({64512.0f, 1.0f, 0.0f}), 1.0);
  EXPECT_EQ(AutomaticScale({64513.0f, 1.0f, 0.0f}), 0.5);
  EXPECT_EQ(AutomaticScale({0.0f, 0.0f, 0.0f}), 1.0);
}
