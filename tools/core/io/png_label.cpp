#include "io/png_label.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "io/error.h"
#include "io/fileio.h"
#include "io/png.h"

// stb_truetype: the implementation lives in this file only, with internal linkage.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#define STBTT_STATIC
#define STB_TRUETYPE_IMPLEMENTATION
#include <stb/stb_truetype.h>
#pragma GCC diagnostic pop

namespace skybake {

struct Font::Impl {
  std::filesystem::path path;
  std::string bytes;  // the font file; stbtt_fontinfo points into it
  stbtt_fontinfo info{};
};

namespace {

// UTF-8 -> code points; an invalid byte becomes U+FFFD.
std::vector<int> DecodeUtf8(std::string_view s) {
  std::vector<int> out;
  for (size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    int n = 0, cp = 0;
    if (b < 0x80) {
      cp = b;
    } else if ((b >> 5) == 6) {
      n = 1, cp = b & 0x1F;
    } else if ((b >> 4) == 14) {
      n = 2, cp = b & 0x0F;
    } else if ((b >> 3) == 30) {
      n = 3, cp = b & 0x07;
    } else {
      n = -1;
    }
    bool ok = n >= 0 && i + n < s.size();
    for (int k = 1; ok && k <= n; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      ok = (c & 0xC0) == 0x80;
      cp = (cp << 6) | (c & 0x3F);
    }
    if (!ok) {
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    out.push_back(cp);
    i += n + 1;
  }
  return out;
}

// A string laid out on its baseline: each glyph's origin (integer pixel + sub-pixel shift).
struct Glyph {
  int cp;
  int x;        // integer origin column
  float shift;  // sub-pixel shift in [0, 1)
};
struct Layout {
  std::vector<Glyph> glyphs;
  float scale = 0.0f;
  double advance = 0.0;
};

Layout LayOut(const stbtt_fontinfo& info, std::string_view utf8, double pixel_height) {
  Layout l;
  l.scale = stbtt_ScaleForPixelHeight(&info, static_cast<float>(pixel_height));
  const std::vector<int> cps = DecodeUtf8(utf8);
  double pen = 0.0;
  for (size_t i = 0; i < cps.size(); ++i) {
    const double fx = std::floor(pen);
    l.glyphs.push_back({cps[i], static_cast<int>(fx), static_cast<float>(pen - fx)});
    int advance = 0, lsb = 0;
    stbtt_GetCodepointHMetrics(&info, cps[i], &advance, &lsb);
    pen += advance * static_cast<double>(l.scale);
    if (i + 1 < cps.size()) pen += stbtt_GetCodepointKernAdvance(&info, cps[i], cps[i + 1]) * static_cast<double>(l.scale);
  }
  l.advance = pen;
  return l;
}

PixelBox GlyphBox(const stbtt_fontinfo& info, const Layout& l, const Glyph& g) {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  stbtt_GetCodepointBitmapBoxSubpixel(&info, g.cp, l.scale, l.scale, g.shift, 0.0f, &x0, &y0, &x1, &y1);
  return {g.x + x0, y0, g.x + x1, y1};
}

PixelBox Union(PixelBox a, PixelBox b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

// The coverage (0-255) of a string over its ink box (row-major, box.width() x box.height();
// overlapping glyphs take the larger coverage).
struct Mask {
  PixelBox box;
  std::vector<uint8_t> alpha;
};

Mask RenderMask(const stbtt_fontinfo& info, std::string_view utf8, double pixel_height) {
  const Layout l = LayOut(info, utf8, pixel_height);
  Mask m;
  for (const Glyph& g : l.glyphs) m.box = Union(m.box, GlyphBox(info, l, g));
  if (m.box.empty()) return m;
  const int w = m.box.width();
  m.alpha.assign(static_cast<size_t>(w) * m.box.height(), 0);
  std::vector<unsigned char> buf;
  for (const Glyph& g : l.glyphs) {
    const PixelBox b = GlyphBox(info, l, g);
    if (b.empty()) continue;
    buf.assign(static_cast<size_t>(b.width()) * b.height(), 0);
    stbtt_MakeCodepointBitmapSubpixel(&info, buf.data(), b.width(), b.height(), b.width(), l.scale, l.scale, g.shift,
                                      0.0f, g.cp);
    for (int y = 0; y < b.height(); ++y) {
      for (int x = 0; x < b.width(); ++x) {
        uint8_t& dst = m.alpha[static_cast<size_t>(b.y0 + y - m.box.y0) * w + (b.x0 + x - m.box.x0)];
        dst = std::max<uint8_t>(dst, buf[static_cast<size_t>(y) * b.width() + x]);
      }
    }
  }
  return m;
}

uint8_t Blend(uint8_t under, uint8_t over, uint8_t a) {
  return static_cast<uint8_t>((over * a + under * (255 - a) + 127) / 255);
}

// Whether `b` (grown by `pad` px) meets any of `drawn`: labels that would touch one already drawn
// are left out, so that crowded ticks stay readable.
bool Overlaps(const PixelBox& b, const std::vector<PixelBox>& drawn, int pad = 2) {
  for (const PixelBox& d : drawn) {
    if (b.x0 - pad < d.x1 && d.x0 < b.x1 + pad && b.y0 - pad < d.y1 && d.y0 < b.y1 + pad) return true;
  }
  return false;
}

PixelBox Moved(PixelBox b, int dx, int dy) { return {b.x0 + dx, b.y0 + dy, b.x1 + dx, b.y1 + dy}; }

}  // namespace

std::filesystem::path Font::ResolvePath() {
  const char* env = std::getenv("SKYBAKE_FONT");
  if (env != nullptr && *env != '\0') return env;
  return kDefaultFontPath;
}

Font Font::Load(const std::filesystem::path& path) {
  auto impl = std::make_shared<Impl>();
  impl->path = path;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(FileLoc{path.string(), 0},
                     "font file not found (the labels of the PNG pictures need a TrueType font: install Debian "
                     "fonts-dejavu-core, e.g. with scripts/setup, or name one with SKYBAKE_FONT)");
  }
  impl->bytes = ReadFileBytes(path);
  const auto* data = reinterpret_cast<const unsigned char*>(impl->bytes.data());
  const int offset = stbtt_GetFontOffsetForIndex(data, 0);
  if (impl->bytes.size() < 12 || offset < 0 || !stbtt_InitFont(&impl->info, data, offset)) {
    throw InputError(FileLoc{path.string(), 0}, "not a TrueType font");
  }
  Font f;
  f.impl_ = std::move(impl);
  return f;
}

const std::filesystem::path& Font::path() const { return impl_->path; }

PixelBox Font::InkBox(std::string_view utf8, double pixel_height) const {
  const Layout l = LayOut(impl_->info, utf8, pixel_height);
  PixelBox box;
  for (const Glyph& g : l.glyphs) box = Union(box, GlyphBox(impl_->info, l, g));
  return box;
}

int Font::Advance(std::string_view utf8, double pixel_height) const {
  return static_cast<int>(std::ceil(LayOut(impl_->info, utf8, pixel_height).advance));
}

int Font::Ascent(double pixel_height) const {
  int ascent = 0, descent = 0, gap = 0;
  stbtt_GetFontVMetrics(&impl_->info, &ascent, &descent, &gap);
  return static_cast<int>(std::ceil(ascent * stbtt_ScaleForPixelHeight(&impl_->info, static_cast<float>(pixel_height))));
}

int Font::Descent(double pixel_height) const {
  int ascent = 0, descent = 0, gap = 0;
  stbtt_GetFontVMetrics(&impl_->info, &ascent, &descent, &gap);
  return static_cast<int>(std::ceil(-descent * stbtt_ScaleForPixelHeight(&impl_->info, static_cast<float>(pixel_height))));
}

Canvas::Canvas(int width, int height, Rgb8 background) : w_(width), h_(height) {
  SKYBAKE_CHECK(width > 0 && height > 0);
  px_.resize(static_cast<size_t>(width) * height * 3);
  for (size_t i = 0; i < px_.size(); i += 3) {
    px_[i] = background.r;
    px_[i + 1] = background.g;
    px_[i + 2] = background.b;
  }
}

Rgb8 Canvas::At(int x, int y) const {
  SKYBAKE_CHECK(x >= 0 && x < w_ && y >= 0 && y < h_);
  const size_t i = (static_cast<size_t>(y) * w_ + x) * 3;
  return {px_[i], px_[i + 1], px_[i + 2]};
}

void Canvas::Put(int x, int y, Rgb8 c) {
  if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
  const size_t i = (static_cast<size_t>(y) * w_ + x) * 3;
  px_[i] = c.r;
  px_[i + 1] = c.g;
  px_[i + 2] = c.b;
}

void Canvas::Fill(PixelBox box, Rgb8 c) {
  for (int y = std::max(0, box.y0); y < std::min(h_, box.y1); ++y)
    for (int x = std::max(0, box.x0); x < std::min(w_, box.x1); ++x) Put(x, y, c);
}

void Canvas::Frame(PixelBox box, Rgb8 c) {
  if (box.empty()) return;
  HLine(box.x0, box.x1, box.y0, c);
  HLine(box.x0, box.x1, box.y1 - 1, c);
  VLine(box.x0, box.y0, box.y1, c);
  VLine(box.x1 - 1, box.y0, box.y1, c);
}

void Canvas::HLine(int x0, int x1, int y, Rgb8 c) { Fill({x0, y, x1, y + 1}, c); }
void Canvas::VLine(int x, int y0, int y1, Rgb8 c) { Fill({x, y0, x + 1, y1}, c); }

void Canvas::Blit(int x, int y, int w, int h, int channels, std::span<const uint8_t> pixels) {
  SKYBAKE_CHECK(channels == 1 || channels == 3);
  SKYBAKE_CHECK_EQ(pixels.size(), static_cast<size_t>(w) * h * channels);
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const size_t s = (static_cast<size_t>(j) * w + i) * channels;
      if (channels == 1) {
        Put(x + i, y + j, {pixels[s], pixels[s], pixels[s]});
      } else {
        Put(x + i, y + j, {pixels[s], pixels[s + 1], pixels[s + 2]});
      }
    }
  }
}

namespace {
int AnchorOffset(const Font& font, std::string_view utf8, double px, Align align) {
  if (align == Align::kLeft) return 0;
  const int adv = font.Advance(utf8, px);
  return align == Align::kCentre ? adv / 2 : adv;
}
}  // namespace

PixelBox Canvas::Text(const Font& font, std::string_view utf8, double pixel_height, int x, int baseline_y, Rgb8 c,
                      Align align) {
  const Mask m = RenderMask(font.impl_->info, utf8, pixel_height);
  const int ox = x - AnchorOffset(font, utf8, pixel_height, align);
  for (int j = 0; j < m.box.height(); ++j) {
    for (int i = 0; i < m.box.width(); ++i) {
      const uint8_t a = m.alpha[static_cast<size_t>(j) * m.box.width() + i];
      const int cx = ox + m.box.x0 + i, cy = baseline_y + m.box.y0 + j;
      if (a == 0 || cx < 0 || cy < 0 || cx >= w_ || cy >= h_) continue;
      const Rgb8 b = At(cx, cy);
      Put(cx, cy, {Blend(b.r, c.r, a), Blend(b.g, c.g, a), Blend(b.b, c.b, a)});
    }
  }
  return {ox + m.box.x0, baseline_y + m.box.y0, ox + m.box.x1, baseline_y + m.box.y1};
}

PixelBox Canvas::TextUp(const Font& font, std::string_view utf8, double pixel_height, int x, int y_anchor, Rgb8 c,
                        Align align) {
  const Mask m = RenderMask(font.impl_->info, utf8, pixel_height);
  // The string's origin; a pixel at (gx, gy) from the origin (gx along the text, gy down from
  // the baseline) lands on column x + gy and row origin - 1 - gx.
  const int origin = y_anchor + AnchorOffset(font, utf8, pixel_height, align);
  for (int j = 0; j < m.box.height(); ++j) {
    for (int i = 0; i < m.box.width(); ++i) {
      const uint8_t a = m.alpha[static_cast<size_t>(j) * m.box.width() + i];
      const int cx = x + m.box.y0 + j, cy = origin - 1 - (m.box.x0 + i);
      if (a == 0 || cx < 0 || cy < 0 || cx >= w_ || cy >= h_) continue;
      const Rgb8 b = At(cx, cy);
      Put(cx, cy, {Blend(b.r, c.r, a), Blend(b.g, c.g, a), Blend(b.b, c.b, a)});
    }
  }
  return {x + m.box.y0, origin - m.box.x1, x + m.box.y1, origin - m.box.x0};
}

std::string Canvas::EncodePng() const { return EncodePng8(w_, h_, 3, px_); }

void DrawScaleBar(Canvas& canvas, const Font& font, const ScaleBar& s) {
  const PixelBox& b = s.bar;
  SKYBAKE_CHECK(!b.empty());
  if (s.vertical) {
    for (int y = b.y0; y < b.y1; ++y) {
      const Rgb8 c = s.colour((b.y1 - 1 - y + 0.5) / b.height());
      canvas.HLine(b.x0, b.x1, y, c);
    }
  } else {
    for (int x = b.x0; x < b.x1; ++x) {
      const Rgb8 c = s.colour((x - b.x0 + 0.5) / b.width());
      canvas.VLine(x, b.y0, b.y1, c);
    }
  }
  canvas.Frame({b.x0 - 1, b.y0 - 1, b.x1 + 1, b.y1 + 1}, s.ink);
  constexpr int kTick = 4, kPad = 2;
  std::vector<PixelBox> drawn;
  for (const ScaleTick& t : s.ticks) {
    const PixelBox ink = font.InkBox(t.label, s.text_px);
    if (s.vertical) {
      const int y = b.y1 - 1 - static_cast<int>(std::lround(std::clamp(t.at, 0.0, 1.0) * (b.height() - 1)));
      canvas.HLine(b.x1 + 1, b.x1 + 1 + kTick, y, s.ink);
      const int x = b.x1 + 1 + kTick + kPad, base = y - (ink.y0 + ink.y1) / 2;
      if (Overlaps(Moved(ink, x, base), drawn)) continue;
      drawn.push_back(canvas.Text(font, t.label, s.text_px, x, base, s.ink));
    } else {
      const int x = b.x0 + static_cast<int>(std::lround(std::clamp(t.at, 0.0, 1.0) * (b.width() - 1)));
      canvas.VLine(x, b.y1 + 1, b.y1 + 1 + kTick, s.ink);
      const int base = b.y1 + 1 + kTick + kPad + font.Ascent(s.text_px), left = x - font.Advance(t.label, s.text_px) / 2;
      if (Overlaps(Moved(ink, left, base), drawn)) continue;
      drawn.push_back(canvas.Text(font, t.label, s.text_px, left, base, s.ink));
    }
  }
  if (!s.title.empty()) canvas.Text(font, s.title, s.text_px, b.x0, b.y0 - 1 - kPad - font.Descent(s.text_px), s.ink);
}

namespace {

// Greedy word wrap of `text` at `px` into lines no wider than `width` (a word wider than that
// gets a line of its own).
std::vector<std::string> Wrap(const Font& font, const std::string& text, double px, int width) {
  std::vector<std::string> lines;
  std::string line, word;
  auto flush_word = [&] {
    if (word.empty()) return;
    const std::string joined = line.empty() ? word : line + " " + word;
    if (line.empty() || font.Advance(joined, px) <= width) {
      line = joined;
    } else {
      lines.push_back(line);
      line = word;
    }
    word.clear();
  };
  for (char c : text) {
    if (c == ' ') {
      flush_word();
    } else {
      word += c;
    }
  }
  flush_word();
  if (!line.empty() || lines.empty()) lines.push_back(line);
  return lines;
}

// `text` at `px` shrunk down to 9 px to fit `width`, then cut with "…" if it still does not.
std::pair<std::string, double> FitLine(const Font& font, std::string text, double px, int width) {
  while (px > 9.0 && font.Advance(text, px) > width) px -= 0.5;
  if (font.Advance(text, px) <= width) return {text, px};
  while (!text.empty() && font.Advance(text + "\u2026", px) > width) {
    do {
      text.pop_back();
    } while (!text.empty() && (static_cast<unsigned char>(text.back()) & 0xC0) == 0x80);
    if (!text.empty() && static_cast<unsigned char>(text.back()) >= 0xC0) text.pop_back();  // a lead byte
  }
  return {text + "\u2026", px};
}

struct SheetLayout {
  static constexpr int kMargin = 10, kGap = 8, kRowLabel = 16, kXAxis = 36, kYAxis = 56, kValue = 84;
  static constexpr double kTitlePx = 15, kSubtitlePx = 11;
  int title_h = 0, header_h = 0, pw = 0, ph = 0, rows = 0, cols = 0, left = 0, bottom = 0;
  int width = 0, height = 0;
  std::vector<std::pair<std::string, double>> title;  // wrapped lines and their sizes

  SheetLayout(const PanelSheet& s, const Font& font) {
    rows = static_cast<int>(s.panels.size());
    SKYBAKE_CHECK(rows > 0 && !s.panels[0].empty());
    cols = static_cast<int>(s.panels[0].size());
    pw = s.panels[0][0].width * s.zoom;
    ph = s.panels[0][0].height * s.zoom;
    int lines = 0;
    for (const std::string& h : s.column_headers) lines = std::max(lines, 1 + static_cast<int>(std::count(h.begin(), h.end(), '\n')));
    header_h = lines * 14 + (lines ? 4 : 0);
    left = s.y_axis.ticks.empty() ? 0 : kYAxis;
    bottom = s.x_axis.ticks.empty() ? 0 : kXAxis;
    width = 2 * kMargin + left + cols * pw + (cols - 1) * kGap + (s.value_ticks.empty() ? 0 : kValue);
    for (size_t i = 0; i < s.title_lines.size(); ++i) {
      const double px = i == 0 ? kTitlePx : kSubtitlePx;
      for (const std::string& l : Wrap(font, s.title_lines[i], px, width - 2 * kMargin)) title.emplace_back(l, px);
    }
    title_h = title.empty() ? 0 : 6 + 16 * static_cast<int>(title.size());
    height = 2 * kMargin + title_h + header_h + rows * (kRowLabel + ph) + (rows - 1) * kGap + bottom;
  }
  int PanelX(int c) const { return kMargin + left + c * (pw + kGap); }
  int PanelY(int r) const { return kMargin + title_h + header_h + r * (kRowLabel + ph + kGap) + kRowLabel; }
};

std::vector<std::string> SplitLines(const std::string& s) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == '\n') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

}  // namespace

std::pair<int, int> PanelSheetSize(const PanelSheet& sheet, const Font& font) {
  const SheetLayout l(sheet, font);
  return {l.width, l.height};
}

std::string RenderPanelSheet(const PanelSheet& s, const Font& font) {
  const SheetLayout l(s, font);
  const Rgb8 bg{40, 40, 40}, ink{232, 232, 232}, dim{175, 175, 175};
  Canvas canvas(l.width, l.height, bg);
  for (size_t i = 0; i < l.title.size(); ++i) {
    canvas.Text(font, l.title[i].first, l.title[i].second, SheetLayout::kMargin,
                SheetLayout::kMargin + 15 + 16 * static_cast<int>(i), i == 0 ? ink : dim);
  }
  auto draw_fitted = [&](const std::string& text, double px, int width, int x, int y, Rgb8 c, Align a) {
    const auto [t, size] = FitLine(font, text, px, width);
    canvas.Text(font, t, size, x, y, c, a);
  };
  const int y_header = SheetLayout::kMargin + l.title_h;
  for (int c = 0; c < l.cols && c < static_cast<int>(s.column_headers.size()); ++c) {
    const std::vector<std::string> lines = SplitLines(s.column_headers[c]);
    for (size_t k = 0; k < lines.size(); ++k) {
      draw_fitted(lines[k], 11, l.pw + SheetLayout::kGap - 2, l.PanelX(c) + l.pw / 2, y_header + 12 + 14 * static_cast<int>(k),
                  k == 0 ? ink : dim, Align::kCentre);
    }
  }
  for (int r = 0; r < l.rows; ++r) {
    SKYBAKE_CHECK_EQ(static_cast<int>(s.panels[r].size()), l.cols);
    const int y0 = l.PanelY(r);
    if (r < static_cast<int>(s.row_labels.size())) {
      const int row_w = l.cols * l.pw + (l.cols - 1) * SheetLayout::kGap;
      draw_fitted(s.row_labels[r], 11, row_w, l.PanelX(0), y0 - 4, ink, Align::kLeft);
    }
    for (int c = 0; c < l.cols; ++c) {
      const GreyPanel& p = s.panels[r][c];
      SKYBAKE_CHECK(p.width * s.zoom == l.pw && p.height * s.zoom == l.ph);
      SKYBAKE_CHECK_EQ(p.grey.size(), static_cast<size_t>(p.width) * p.height);
      const int x0 = l.PanelX(c);
      for (int y = 0; y < l.ph; ++y) {
        for (int x = 0; x < l.pw; ++x) {
          const uint8_t g = p.grey[static_cast<size_t>(y / s.zoom) * p.width + x / s.zoom];
          canvas.Put(x0 + x, y0 + y, {g, g, g});
        }
      }
    }
    if (!s.y_axis.ticks.empty()) {  // left of the first column, every row
      const int x = l.PanelX(0);
      std::vector<PixelBox> drawn;
      for (const ScaleTick& t : s.y_axis.ticks) {
        const int y = y0 + l.ph - 1 - static_cast<int>(std::lround(std::clamp(t.at, 0.0, 1.0) * (l.ph - 1)));
        canvas.HLine(x - 4, x, y, dim);
        const PixelBox ink_box = font.InkBox(t.label, 9);
        const int base = std::clamp(y - (ink_box.y0 + ink_box.y1) / 2, y0 + 8, y0 + l.ph);
        const int left = x - 6 - font.Advance(t.label, 9);
        if (Overlaps(Moved(ink_box, left, base), drawn)) continue;
        drawn.push_back(canvas.Text(font, t.label, 9, left, base, dim));
      }
      const auto [title, px] = FitLine(font, s.y_axis.title, 10, l.ph);
      canvas.TextUp(font, title, px, SheetLayout::kMargin + 10, y0 + l.ph / 2, dim);
    }
    if (!s.value_ticks.empty()) {
      SKYBAKE_CHECK_EQ(static_cast<int>(s.value_ticks.size()), l.rows);
      ScaleBar bar;
      const int xb = l.PanelX(l.cols - 1) + l.pw + 12;
      bar.bar = {xb, y0, xb + 12, y0 + l.ph};
      bar.vertical = true;
      bar.colour = [](double f) {
        const auto g = static_cast<uint8_t>(std::lround(std::clamp(f, 0.0, 1.0) * 255.0));
        return Rgb8{g, g, g};
      };
      bar.ticks = s.value_ticks[r];
      bar.text_px = 9;
      bar.ink = dim;
      DrawScaleBar(canvas, font, bar);
      const auto [title, px] = FitLine(font, s.value_title, 10, l.ph);
      canvas.TextUp(font, title, px, l.width - SheetLayout::kMargin, y0 + l.ph / 2, dim);
    }
  }
  if (!s.x_axis.ticks.empty()) {  // under the bottom row
    const int y = l.PanelY(l.rows - 1) + l.ph;
    for (int c = 0; c < l.cols; ++c) {
      const int x0 = l.PanelX(c);
      std::vector<PixelBox> drawn;
      for (const ScaleTick& t : s.x_axis.ticks) {
        const int x = x0 + static_cast<int>(std::lround(std::clamp(t.at, 0.0, 1.0) * (l.pw - 1)));
        canvas.VLine(x, y, y + 4, dim);
        const int adv = font.Advance(t.label, 9);
        const int left = std::clamp(x - adv / 2, x0, x0 + l.pw - adv);  // inside the panel's width
        if (Overlaps(Moved(font.InkBox(t.label, 9), left, y + 14), drawn)) continue;
        drawn.push_back(canvas.Text(font, t.label, 9, left, y + 14, dim));
      }
      draw_fitted(s.x_axis.title, 10, l.pw + SheetLayout::kGap - 2, x0 + l.pw / 2, y + 29, dim, Align::kCentre);
    }
  }
  return canvas.EncodePng();
}

std::vector<double> NiceTicks(double lo, double hi, int max_ticks) {
  SKYBAKE_CHECK(hi > lo && max_ticks >= 1);
  const int k0 = static_cast<int>(std::floor(std::log10(hi - lo))) - 3;
  for (int k = k0; k < k0 + 8; ++k) {
    for (int m : {1, 2, 5}) {
      // i m 10^k as (i m) / 10^-k for k < 0: integer times or over an exact power of ten, so
      // 0.05 and -0.1 are the doubles those literals give.
      const double p10 = std::pow(10.0, std::abs(k));
      const double step = k < 0 ? m / p10 : m * p10;
      const double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
      if (last - first + 1 <= max_ticks) {
        std::vector<double> out;
        for (double i = first; i <= last; i += 1.0) out.push_back(k < 0 ? i * m / p10 : i * m * p10);
        return out;
      }
    }
  }
  return {lo, hi};
}

double RoundSignificant(double v, int digits) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  const double e = std::floor(std::log10(std::fabs(v))) - (digits - 1);
  const double p = std::pow(10.0, e);
  return std::round(v / p) * p;
}

std::string FormatLabelNumber(double v, int digits) {
  v = RoundSignificant(v, digits);
  if (v == 0.0) return "0";
  const int mag = static_cast<int>(std::floor(std::log10(std::fabs(v))));
  const int decimals = std::max(0, digits - 1 - mag);
  std::string s = fmt::format("{:.{}f}", std::fabs(v), decimals);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return v < 0 ? "\u2212" + s : s;
}

}  // namespace skybake
