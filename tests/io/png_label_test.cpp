// io/png_label.h: text drawn from the TrueType font stays inside the ink box the font states
// (and fills it: ink reaches every side), rotated text likewise, a missing font is bad input
// naming the file, and the scale helpers give the numbers they promise.
#include "io/png_label.h"

#include <gtest/gtest.h>

#include "io/error.h"
#include "io/png.h"

namespace skybake {
namespace {

const Rgb8 kBlack{0, 0, 0}, kWhite{255, 255, 255};

// The bounding box of every pixel that is not the background (black).
PixelBox InkOf(const Canvas& c) {
  PixelBox b{c.width(), c.height(), 0, 0};
  for (int y = 0; y < c.height(); ++y) {
    for (int x = 0; x < c.width(); ++x) {
      const Rgb8 p = c.At(x, y);
      if (p.r || p.g || p.b) b = {std::min(b.x0, x), std::min(b.y0, y), std::max(b.x1, x + 1), std::max(b.y1, y + 1)};
    }
  }
  return b;
}

TEST(PngLabel, TextInkLiesInsideItsStatedBoxAndReachesEverySide) {
  const Font font = Font::Load();
  for (const char* s : {"sun 60°", "white = 8200 cd/m²", "gjpqy|ÅÉ", "−4 °", "i"}) {
    for (double px : {9.0, 13.0, 21.5}) {
      Canvas c(300, 80, kBlack);
      const PixelBox stated = font.InkBox(s, px);
      ASSERT_FALSE(stated.empty()) << s;
      const PixelBox drawn = c.Text(font, s, px, 20, 50, kWhite);
      EXPECT_EQ(drawn.x0, stated.x0 + 20);
      EXPECT_EQ(drawn.y0, stated.y0 + 50);
      EXPECT_EQ(drawn.x1, stated.x1 + 20);
      EXPECT_EQ(drawn.y1, stated.y1 + 50);
      const PixelBox ink = InkOf(c);
      ASSERT_FALSE(ink.empty()) << s;
      // None outside ...
      EXPECT_GE(ink.x0, drawn.x0) << s << " " << px;
      EXPECT_GE(ink.y0, drawn.y0) << s << " " << px;
      EXPECT_LE(ink.x1, drawn.x1) << s << " " << px;
      EXPECT_LE(ink.y1, drawn.y1) << s << " " << px;
      // ... and the box is tight (stb_truetype's boxes are the outline's, rounded outwards).
      EXPECT_LE(ink.x0 - drawn.x0, 1) << s << " " << px;
      EXPECT_LE(ink.y0 - drawn.y0, 1) << s << " " << px;
      EXPECT_LE(drawn.x1 - ink.x1, 1) << s << " " << px;
      EXPECT_LE(drawn.y1 - ink.y1, 1) << s << " " << px;
      // Text sits on its baseline: capitals and digits end at it, descenders go below.
      EXPECT_LT(drawn.y0, 50);
    }
  }
}

TEST(PngLabel, DescendersGoBelowTheBaselineAndAscentsAboveIt) {
  const Font font = Font::Load();
  const PixelBox flat = font.InkBox("EH60", 20);
  EXPECT_LE(flat.y1, 1);  // digits and capitals sit on the baseline (round ones overshoot it by a pixel)
  EXPECT_LT(flat.y0, -10);
  EXPECT_GT(font.InkBox("gjpqy", 20).y1, 2);
  EXPECT_GT(font.Ascent(20), 10);
  EXPECT_GT(font.Descent(20), 2);
  EXPECT_TRUE(font.InkBox("   ", 20).empty());
  EXPECT_GT(font.Advance("   ", 20), 5);
}

TEST(PngLabel, AlignmentMovesTheStringByItsAdvance) {
  const Font font = Font::Load();
  Canvas c(200, 40, kBlack);
  const int adv = font.Advance("depth", 12);
  const PixelBox left = c.Text(font, "depth", 12, 100, 30, kWhite, Align::kLeft);
  const PixelBox right = c.Text(font, "depth", 12, 100, 30, kWhite, Align::kRight);
  const PixelBox centre = c.Text(font, "depth", 12, 100, 30, kWhite, Align::kCentre);
  EXPECT_EQ(left.x0 - right.x0, adv);
  EXPECT_EQ(left.x0 - centre.x0, adv / 2);
}

TEST(PngLabel, RotatedTextInkLiesInsideItsBoxAndReadsUpwards) {
  const Font font = Font::Load();
  Canvas c(60, 200, kBlack);
  const PixelBox flat = font.InkBox("elevation", 14);
  const PixelBox drawn = c.TextUp(font, "elevation", 14, 40, 100, kWhite, Align::kCentre);
  EXPECT_EQ(drawn.width(), flat.height());
  EXPECT_EQ(drawn.height(), flat.width());
  EXPECT_LE(drawn.x1, 40 + flat.y1);  // ink to the left of the baseline column (x1 - 1 = last column)
  const PixelBox ink = InkOf(c);
  EXPECT_GE(ink.x0, drawn.x0);
  EXPECT_GE(ink.y0, drawn.y0);
  EXPECT_LE(ink.x1, drawn.x1);
  EXPECT_LE(ink.y1, drawn.y1);
  EXPECT_LE(drawn.x1 - ink.x1 + ink.x0 - drawn.x0 + drawn.y1 - ink.y1 + ink.y0 - drawn.y0, 4);
  // Centred on y = 100 within a pixel of half the advance.
  EXPECT_NEAR((drawn.y0 + drawn.y1) / 2.0, 100.0, font.Advance("elevation", 14) / 2.0 - flat.width() / 2.0 + 2.0);
}

TEST(PngLabel, BlendingKeepsTheBackgroundWhereThereIsNoInk) {
  const Font font = Font::Load();
  Canvas c(50, 30, {10, 20, 30});
  const PixelBox drawn = c.Text(font, "o", 20, 10, 25, kWhite);
  EXPECT_EQ(c.At(0, 0).r, 10);
  EXPECT_EQ(c.At(49, 29).b, 30);
  // The middle of an "o" is its counter (background); its left side is inked.
  bool inked = false;
  for (int x = drawn.x0; x < drawn.x0 + 3; ++x) inked |= c.At(x, (drawn.y0 + drawn.y1) / 2).r > 128;
  EXPECT_TRUE(inked);
  EXPECT_EQ(c.At((drawn.x0 + drawn.x1) / 2, (drawn.y0 + drawn.y1) / 2).g, 20);
}

TEST(PngLabel, MissingFontIsBadInputNamingTheFile) {
  try {
    Font::Load("/nonexistent/skybake/NoSuchFont.ttf");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/skybake/NoSuchFont.ttf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fonts-dejavu-core"), std::string::npos) << e.what();
  }
}

TEST(PngLabel, ScaleBarDrawsTheColourAtEachEndAndTicks) {
  const Font font = Font::Load();
  Canvas c(200, 60, kBlack);
  ScaleBar s;
  s.bar = {20, 20, 180, 30};
  s.colour = [](double f) { return Rgb8{static_cast<uint8_t>(255 * f), 0, static_cast<uint8_t>(255 * (1 - f))}; };
  s.ticks = {{0.0, "0"}, {1.0, "1"}};
  s.title = "value";
  DrawScaleBar(c, font, s);
  EXPECT_LT(c.At(20, 25).r, 5);   // the start: f ~ 0
  EXPECT_GT(c.At(179, 25).r, 250);  // the end: f ~ 1
  EXPECT_EQ(c.At(20, 32).r, 230);   // tick mark below the left end
  EXPECT_EQ(c.At(179, 32).r, 230);
  const PixelBox ink = InkOf(c);
  EXPECT_LT(ink.y0, 18);  // the title above the bar
  EXPECT_GT(ink.y1, 38);  // labels below the ticks
  // PNG round trip.
  int w = 0, h = 0, ch = 0;
  const std::vector<uint8_t> px = DecodePng8(c.EncodePng(), "bar", &w, &h, &ch);
  EXPECT_EQ(w, 200);
  EXPECT_EQ(h, 60);
  EXPECT_EQ(ch, 3);
  EXPECT_EQ(px, c.rgb());
}

TEST(PngLabel, NiceTicksAndNumbers) {
  EXPECT_EQ(NiceTicks(-0.1, 0.1, 5), (std::vector<double>{-0.1, -0.05, 0.0, 0.05, 0.1}));
  EXPECT_EQ(NiceTicks(0, 8200, 5), (std::vector<double>{0, 2000, 4000, 6000, 8000}));
  EXPECT_EQ(NiceTicks(0, 1, 3), (std::vector<double>{0, 0.5, 1}));
  EXPECT_EQ(FormatLabelNumber(8213.7), "8210");
  EXPECT_EQ(FormatLabelNumber(0.25), "0.25");
  EXPECT_EQ(FormatLabelNumber(4.875), "4.88");
  EXPECT_EQ(FormatLabelNumber(-10), "\u221210");
  EXPECT_EQ(FormatLabelNumber(0), "0");
  EXPECT_EQ(FormatLabelNumber(1e-3), "0.001");
  EXPECT_DOUBLE_EQ(RoundSignificant(8213.7, 2), 8200);
}

}  // namespace
}  // namespace skybake
