#include "fog/fog_residual_png.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace skybake::fog {

namespace {

// Diverging colours for a relative error: blue (-range) - white (0) - red (+range); grey = excluded.
std::array<uint8_t, 3> Diverging(float e, double range) {
  if (!std::isfinite(e)) return {96, 96, 96};
  const double t = std::clamp(e / range, -1.0, 1.0);
  const double lo[3] = {59, 76, 192}, hi[3] = {180, 4, 38};  // Moreland's cool-warm ends (sRGB codes)
  std::array<uint8_t, 3> c;
  for (int k = 0; k < 3; ++k) {
    const double end = t < 0 ? lo[k] : hi[k];
    c[k] = static_cast<uint8_t>(std::lround(255.0 + (end - 255.0) * std::fabs(t)));
  }
  return c;
}


}  // namespace

// One drawing: the layout constants, the two panels, the row labels and the key share the
// canvas's coordinates, so they stay together.
std::string ResidualPng(const FogRender& r, const FogProducts& p, const Font& font) {
  constexpr int kPx = 5, kGap = 4, kMargin = 10, kLabel = 104, kPanelGap = 24, kTitle = 50, kHeader = 38;
  constexpr double kRange = 0.1;  // full scale: +-10 %
  const Rgb8 bg{32, 32, 32}, ink{232, 232, 232}, dim{170, 170, 170};
  const int nx = static_cast<int>(r.depth_x.size()), ne = static_cast<int>(r.elevation_deg.size());
  const int na = static_cast<int>(r.azimuth_deg.size()), ns = static_cast<int>(r.tables.size());
  const int tile_w = nx * kPx, tile_h = ne * kPx;
  const int panel_w = na * (tile_w + kGap) - kGap;
  const int key_h = std::max(tile_h, 30) + 64;
  const int W = std::max(2 * kMargin + kLabel + 2 * panel_w + kPanelGap, 640);
  const int H = 2 * kMargin + kTitle + kHeader + ns * (tile_h + kGap) + key_h;
  Canvas canvas(W, H, bg);
  auto colour = [&](float e) {
    const auto c = Diverging(e, kRange);
    return Rgb8{c[0], c[1], c[2]};
  };
  auto fit = [&](const std::string& text, double px, int width) {
    while (px > 8.0 && font.Advance(text, px) > width) px -= 0.5;
    return px;
  };
  const std::string t1 = fmt::format("fog-fit residuals of {}: the evaluator on the packed LUTs against the reference fog", p.sky);
  const std::string t2 =
      "Colour: relative luminance error Y_model / Y_reference \u2212 1 (\u00b110 % full scale). Rows: depth tables (sun "
      "angle); columns: view azimuth from the sun; in each tile depth runs right, elevation up (key at the bottom).";
  canvas.Text(font, t1, fit(t1, 15, W - 2 * kMargin), kMargin, kMargin + 15, ink);
  canvas.Text(font, t2, fit(t2, 11, W - 2 * kMargin), kMargin, kMargin + 36, dim);
  const int y_header = kMargin + kTitle, y_tiles = y_header + kHeader;
  const int x_panels = kMargin + kLabel;
  const char* panel_name[2] = {"fog", "shadowed fog"};
  for (int prod = 0; prod < 2; ++prod) {
    const int px0 = x_panels + prod * (panel_w + kPanelGap);
    canvas.Text(font, panel_name[prod], 14, px0 + panel_w / 2, y_header + 14, ink, Align::kCentre);
    canvas.HLine(px0, px0 + panel_w, y_header + 19, dim);
    for (int a = 0; a < na; ++a) {
      const std::string az = (a == 0 ? "azimuth " : "") + FormatLabelNumber(r.azimuth_deg[a], 3) + "\u00b0";
      canvas.Text(font, az, fit(az, 10, tile_w + kGap), px0 + a * (tile_w + kGap) + tile_w / 2, y_header + 33, dim,
                  Align::kCentre);
    }
    const auto& maps = prod ? p.residual_shadowed_eval : p.residual_fog_eval;
    for (int s = 0; s < ns; ++s) {
      for (int a = 0; a < na; ++a) {
        const int x0 = px0 + a * (tile_w + kGap), y0 = y_tiles + s * (tile_h + kGap);
        for (int e = 0; e < ne; ++e) {
          for (int j = 0; j < nx; ++j) {
            canvas.Fill({x0 + j * kPx, y0 + (ne - 1 - e) * kPx, x0 + (j + 1) * kPx, y0 + (ne - e) * kPx},
                        colour(maps[s][r.TableIndex(e, a, j)]));
          }
        }
      }
    }
  }
  for (int s = 0; s < ns; ++s) {
    const double sz = r.tables[s].sun_zenith_deg;
    const int y0 = y_tiles + s * (tile_h + kGap);
    const int mid = y0 + tile_h / 2;
    canvas.Text(font, "sun zenith " + FormatLabelNumber(sz, 4) + "\u00b0", 10.5, kMargin, mid - 1, ink);
    canvas.Text(font, "elevation " + FormatLabelNumber(90.0 - sz, 4) + "\u00b0", 10, kMargin, mid + 11, dim);
    if (s < static_cast<int>(p.table_in_fit.size()) && !p.table_in_fit[s]) {
      canvas.Text(font, "not in the fit", 9, kMargin, mid + 22, dim);
    }
  }

  // Key: one tile with its axes, and the colour scale.
  const int yk = y_tiles + ns * (tile_h + kGap) + 18;
  const int xk = x_panels + 40;
  canvas.Text(font, "key (one tile):", 11, kMargin, yk + tile_h / 2 + 4, ink);
  canvas.Frame({xk - 1, yk - 1, xk + tile_w + 1, yk + tile_h + 1}, dim);
  for (int e = 0; e < ne; ++e) {
    for (int j = 0; j < nx; ++j) {
      const uint8_t g = static_cast<uint8_t>(70 + 120 * ((e + j) % 2));
      canvas.Fill({xk + j * kPx, yk + (ne - 1 - e) * kPx, xk + (j + 1) * kPx, yk + (ne - e) * kPx}, {g, g, g});
    }
  }
  for (int j : {0, nx - 1}) {  // depth ticks under the first and last sample columns
    const int x = xk + j * kPx + kPx / 2;
    canvas.VLine(x, yk + tile_h + 1, yk + tile_h + 5, dim);
    canvas.Text(font, FormatLabelNumber(r.depth_x[j], 2), 9, x, yk + tile_h + 15, dim, Align::kCentre);
  }
  canvas.Text(font,
              fmt::format("depth x \u2192 (fraction of the path to the fog's top at {} m), one column per sample",
                          FormatLabelNumber(r.cut_altitude_m, 4)),
              10, xk, yk + tile_h + 29, dim);
  for (int e : {0, ne - 1}) {  // elevation ticks left of the bottom and top sample rows
    const int y = yk + (ne - 1 - e) * kPx + kPx / 2;
    canvas.HLine(xk - 5, xk - 1, y, dim);
    canvas.Text(font, FormatLabelNumber(r.elevation_deg[e], 3) + "\u00b0", 9, xk - 7, y + 3, dim, Align::kRight);
  }
  canvas.TextUp(font, "elevation \u2192", 9, xk - 30, yk + tile_h / 2, dim, Align::kCentre);

  ScaleBar bar;
  const int xb = xk + tile_w + 160, bar_w = std::min(300, W - kMargin - 20 - xb);
  bar.bar = {xb, yk + 14, xb + std::max(bar_w, 60), yk + 26};
  bar.colour = [&](double f) { return colour(static_cast<float>((2.0 * f - 1.0) * kRange)); };
  for (double v : NiceTicks(-100 * kRange, 100 * kRange, 5)) {
    bar.ticks.push_back({(v / 100 + kRange) / (2 * kRange), (v > 0 ? "+" : "") + FormatLabelNumber(v, 3) + " %"});
  }
  bar.title = "relative luminance error (model / reference \u2212 1)";
  bar.text_px = 10;
  bar.ink = dim;
  DrawScaleBar(canvas, font, bar);
  const int xs = xb, ys = yk + 50;
  canvas.Fill({xs, ys, xs + 12, ys + 10}, colour(std::numeric_limits<float>::quiet_NaN()));
  canvas.Text(font, "no reference (excluded)", 10, xs + 18, ys + 9, dim);
  return canvas.EncodePng();
}


}  // namespace skybake::fog
