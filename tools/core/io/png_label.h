// Labelled pictures for people: text, lines, rectangles, colour scales and image panels drawn
// on an 8-bit RGB canvas that is encoded as PNG (io/png.h). Every picture skybake writes for a
// person to judge (lut-pack's contact sheet, fog-fit's residual maps, the cloud texture
// previews) is composed here; the tools only choose what goes where.
//
// Text is rasterised from a TrueType font by stb_truetype (Debian libstb-dev), by default
// DejaVu Sans (Debian fonts-dejavu-core, /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf);
// the environment variable SKYBAKE_FONT names another file. A glyph's coverage (0-255,
// antialiased) blends the text colour over the canvas: out = (c a + b (255 - a)) / 255 in
// integers, rounded half up. Strings are UTF-8 (°, ², ±, −, × are in the font).
//
// Determinism: drawing is serial integer arithmetic on the canvas and stb_truetype's
// rasteriser is single-threaded float code, so the same calls give the same bytes at any
// thread count.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace skybake {

struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
};

// A pixel rectangle [x0, x1) x [y0, y1) (x right, y down). Empty when x1 <= x0 or y1 <= y0.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

inline constexpr const char* kDefaultFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

// A TrueType font. Immutable after Load; copies share the font data.
class Font {
 public:
  // $SKYBAKE_FONT when set and not empty, else kDefaultFontPath.
  static std::filesystem::path ResolvePath();
  // Reads and parses the font file. A missing or unreadable file, or one that is not a TrueType
  // font: InputError(path) saying which package provides the default font.
  static Font Load(const std::filesystem::path& path = ResolvePath());

  const std::filesystem::path& path() const;
  // The ink box of `utf8` drawn at `pixel_height` (ascent - descent, px) with its origin (the
  // left end of the baseline) at (0, 0): every pixel the text covers lies inside it, and ink
  // reaches each of its sides (the union of the glyphs' bitmap boxes). Empty for "" or spaces.
  PixelBox InkBox(std::string_view utf8, double pixel_height) const;
  // The horizontal advance of the string (px, rounded up): where the next string would start.
  int Advance(std::string_view utf8, double pixel_height) const;
  // Ascent (above the baseline, > 0) and descent (below it, > 0) of the font at this size (px).
  int Ascent(double pixel_height) const;
  int Descent(double pixel_height) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  friend class Canvas;
};

// Horizontal placement of a string relative to its anchor x: the anchor is the left end, the
// centre or the right end of the string's advance.
enum class Align { kLeft, kCentre, kRight };

class Canvas {
 public:
  Canvas(int width, int height, Rgb8 background);

  int width() const { return w_; }
  int height() const { return h_; }
  // Interleaved RGB, rows top to bottom.
  const std::vector<uint8_t>& rgb() const { return px_; }
  Rgb8 At(int x, int y) const;

  // Pixels outside the canvas are skipped (clipped) by every drawing call.
  void Put(int x, int y, Rgb8 c);
  void Fill(PixelBox box, Rgb8 c);
  // A one-pixel outline just inside `box`.
  void Frame(PixelBox box, Rgb8 c);
  void HLine(int x0, int x1, int y, Rgb8 c);  // [x0, x1)
  void VLine(int x, int y0, int y1, Rgb8 c);  // [y0, y1)
  // Copies a w x h image (channels 1 = grey or 3 = RGB, rows top to bottom) with its top-left
  // corner at (x, y).
  void Blit(int x, int y, int w, int h, int channels, std::span<const uint8_t> pixels);
  // Draws `utf8` with its baseline at y and x the anchor of `align`; returns the ink box on the
  // canvas (Font::InkBox moved to where the string was drawn).
  PixelBox Text(const Font& font, std::string_view utf8, double pixel_height, int x, int baseline_y, Rgb8 c,
                Align align = Align::kLeft);
  // The same text turned 90 degrees counter-clockwise (it reads upwards): its baseline is the
  // column x (ink to the left of it), `align` places it along y about y_anchor (kLeft: the string
  // starts at y_anchor and runs up; kCentre: centred on it). Returns the ink box.
  PixelBox TextUp(const Font& font, std::string_view utf8, double pixel_height, int x, int y_anchor, Rgb8 c,
                  Align align = Align::kCentre);

  // 8-bit RGB PNG (io/png.h EncodePng8).
  std::string EncodePng() const;

 private:
  int w_, h_;
  std::vector<uint8_t> px_;
};

// A tick of a scale: position along the bar (0 = the start, 1 = the end) and its label.
struct ScaleTick {
  double at = 0.0;
  std::string label;
};

// A labelled scale bar. The bar fills `bar` with colour(f), f in [0, 1] from the left end
// (horizontal) or the bottom end (vertical) to the other; each tick is a 4 px mark outside the
// bar with its label beyond it (below a horizontal bar, to the right of a vertical one); a
// one-pixel frame of `ink` surrounds the bar. `title` (may be empty) is drawn above the bar.
struct ScaleBar {
  PixelBox bar;
  bool vertical = false;
  std::function<Rgb8(double)> colour;
  std::vector<ScaleTick> ticks;
  std::string title;
  double text_px = 11.0;
  Rgb8 ink{230, 230, 230};
};
void DrawScaleBar(Canvas& canvas, const Font& font, const ScaleBar& scale);

// A grid of grey data panels with labels: the layout of the cloud texture previews.
//
//   title_lines      the first in 15 px, the others in 11 px, above everything;
//   column_headers   above each column ('\n' splits a header into lines);
//   row_labels       one line above each row of panels;
//   panels           [row][column], every one the same size, grey 0-255, rows top to bottom,
//                    shown `zoom` x `zoom` pixels per value;
//   x_axis, y_axis   ticks (at: 0 = left / bottom edge of a panel, 1 = right / top edge) and a
//                    title, under the bottom row's panels and left of the first column's
//                    (no ticks: no axis);
//   value_ticks      per row: the grey scale right of it (at: grey / 255), titled value_title.
// Layout (px): margin 10; title lines word-wrapped to the sheet's width, 16 per line plus 6;
// column headers 14 per line plus 4; a y axis 56 wide; panels 8 apart with a 16 px row label
// above each row; the value scale 84 wide; the x axis 36 high. Headers and row labels that do
// not fit shrink to 9 px and are then cut with "…"; tick labels that would touch one already
// drawn are left out.
struct PanelAxis {
  std::string title;
  std::vector<ScaleTick> ticks;
};
struct GreyPanel {
  int width = 0, height = 0;
  std::vector<uint8_t> grey;
};
struct PanelSheet {
  std::vector<std::string> title_lines;
  std::vector<std::string> column_headers;
  std::vector<std::string> row_labels;
  std::vector<std::vector<GreyPanel>> panels;
  int zoom = 1;
  PanelAxis x_axis, y_axis;
  std::vector<std::vector<ScaleTick>> value_ticks;  // empty, or one list per row
  std::string value_title;
};
// The PNG's width and height.
std::pair<int, int> PanelSheetSize(const PanelSheet& sheet, const Font& font);
std::string RenderPanelSheet(const PanelSheet& sheet, const Font& font);

// Tick values for a linear axis over [lo, hi]: multiples of 1, 2 or 5 x 10^k, the finest step
// that gives at most max_ticks values inside [lo, hi] (lo and hi themselves when they are
// multiples).
std::vector<double> NiceTicks(double lo, double hi, int max_ticks);
// A number for a label with at most `digits` significant digits, without trailing zeros or
// exponent for 1e-4 <= |v| < 1e7 ("8200", "0.25", "-10"); "−" (U+2212) for negatives.
std::string FormatLabelNumber(double v, int digits = 3);
// v rounded to `digits` significant digits (the value FormatLabelNumber shows).
double RoundSignificant(double v, int digits);

}  // namespace skybake
