#include "lut/contact_sheet.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "io/error.h"
#include "lut/directions.h"

namespace skybake::lut {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
const Rgb8 kBackground{36, 36, 36}, kInk{232, 232, 232}, kDim{170, 170, 170}, kRim{96, 96, 96};

// The largest size <= px at which `s` fits in max_width (whole pixels down to 8 px).
double FitPx(const Font& font, const std::string& s, double px, int max_width) {
  while (px > 8.0 && font.Advance(s, px) > max_width) px -= 0.5;
  return px;
}

std::string Degrees(double v) { return FormatLabelNumber(v, 3) + "\u00b0"; }

}  // namespace

ContactSheet RenderContactSheet(const std::vector<ContactSheetSky>& skies, const std::string& time_mapping_name,
                                const ColorConfig& config, const Font& font, const std::vector<double>& elevations) {
  using L = ContactSheetLayout;
  SKYBAKE_CHECK(!skies.empty() && !elevations.empty());
  const int rows = static_cast<int>(skies.size()), cols = static_cast<int>(elevations.size());
  const int C = L::kCell;
  const DirectionGrid grid{DirectionMapping::kFisheye, C, C};

  // Decode every cell: Linear Rec.2020 (cd/m^2); outside the fisheye disc stays NaN.
  const size_t cell_n = static_cast<size_t>(C) * C;
  std::vector<std::vector<float>> rgb(static_cast<size_t>(rows) * cols, std::vector<float>(cell_n * 3, 0.0f));
  std::vector<uint8_t> inside(cell_n, 0), counted_by_col(static_cast<size_t>(cols) * cell_n, 0);
  for (int y = 0; y < C; ++y)
    for (int x = 0; x < C; ++x) inside[static_cast<size_t>(y) * C + x] = grid.TexelDirection(x, y).has_value();
  for (int c = 0; c < cols; ++c) {
    const double sun_zenith = (90.0 - elevations[c]) * kDeg;
    const std::array<double, 3> sun{std::sin(sun_zenith), 0.0, std::cos(sun_zenith)};
    for (int y = 0; y < C; ++y) {
      for (int x = 0; x < C; ++x) {
        const auto d = grid.TexelDirection(x, y);
        if (!d) continue;
        const double cosang = (*d)[0] * sun[0] + (*d)[1] * sun[1] + (*d)[2] * sun[2];
        counted_by_col[static_cast<size_t>(c) * cell_n + static_cast<size_t>(y) * C + x] =
            cosang < std::cos(L::kSunExclusionDeg * kDeg);
      }
    }
  }
  const size_t tasks = static_cast<size_t>(rows) * cols * C;  // one pixel row of one cell each
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tasks), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t t = range.begin(); t != range.end(); ++t) {
      const int y = static_cast<int>(t % C);
      const size_t cell = t / C;
      const int r = static_cast<int>(cell / cols), c = static_cast<int>(cell % cols);
      const double sun_zenith = (90.0 - elevations[c]) * kDeg;
      std::vector<float>& out = rgb[cell];
      for (int x = 0; x < C; ++x) {
        const auto d = grid.TexelDirection(x, y);
        if (!d) continue;
        const std::array<double, 3> v = skies[r].decoder->Radiance(*d, sun_zenith);
        for (int k = 0; k < 3; ++k) out[(static_cast<size_t>(y) * C + x) * 3 + k] = static_cast<float>(v[k]);
      }
    }
  });

  // One exposure per column: white = the 99th percentile of Y over its counted pixels.
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  ContactSheet sheet;
  sheet.sun_elevation_deg = elevations;
  std::vector<ColorProcessor> display(cols);
  for (int c = 0; c < cols; ++c) {
    std::vector<float> lum;
    for (int r = 0; r < rows; ++r) {
      std::vector<float> xyz = rgb[static_cast<size_t>(r) * cols + c];
      to_xyz.Apply(xyz);
      for (size_t i = 0; i < cell_n; ++i) {
        if (counted_by_col[static_cast<size_t>(c) * cell_n + i]) lum.push_back(xyz[i * 3 + 1]);
      }
    }
    std::sort(lum.begin(), lum.end());
    const double p = lum.empty() ? 0.0 : lum[static_cast<size_t>(std::floor(L::kPercentile * (lum.size() - 1)))];
    const double white = std::max(RoundSignificant(p, 2), 1e-6);
    sheet.white_cd_m2.push_back(white);
    DisplayView view;
    view.white_cd_m2 = white;
    display[c] = config.Display(ocio_names::kLinearRec2020, view);
  }

  // Draw.
  sheet.width = L::Width(cols);
  sheet.height = L::Height(rows);
  Canvas canvas(sheet.width, sheet.height, kBackground);
  const int text_w = sheet.width - 2 * L::kMargin;
  int y = L::kMargin;
  std::string names;
  for (const ContactSheetSky& s : skies) names += (names.empty() ? "" : ", ") + s.name;
  const SkyLutDecoder& first = *skies[0].decoder;
  const std::vector<std::string> title = {
      fmt::format("Sky LUT contact sheet: {} (time mapping {}, {} sun slices)", names, time_mapping_name, first.slices()),
      "Each cell: the sky a game decodes from the packed R11G11B10F LUT (lut-pack's reference decoder), not the float render.",
      "View: upward fisheye (equidistant): zenith at the centre, horizon on the rim, sun azimuth to the right.",
      fmt::format("Display: sRGB, un-tone-mapped (OCIO). One exposure per column: white = the column's {:g}th percentile "
                  "luminance, more than {:g}\u00b0 from the sun.",
                  100 * L::kPercentile, L::kSunExclusionDeg)};
  canvas.Text(font, title[0], FitPx(font, title[0], 16, text_w), L::kMargin, y + 16, kInk);
  for (size_t i = 1; i < title.size(); ++i) {
    canvas.Text(font, title[i], FitPx(font, title[i], 12, text_w), L::kMargin, y + 20 + 16 * static_cast<int>(i), kDim);
  }
  y += L::kTitleHeight;

  // Column headers and their luminance scales.
  const int x_cells = L::kMargin + L::kLabelWidth;
  const int bar_y0 = y + 38, bar_y1 = y + 48;
  canvas.Text(font, "luminance", 11, x_cells - 10, bar_y0 + 6, kDim, Align::kRight);
  canvas.Text(font, "(cd/m\u00b2)", 11, x_cells - 10, bar_y0 + 20, kDim, Align::kRight);
  for (int c = 0; c < cols; ++c) {
    const int x0 = x_cells + c * (C + L::kColumnGap);
    canvas.Text(font, "sun " + Degrees(elevations[c]), 14, x0 + C / 2, y + 15, kInk, Align::kCentre);
    const double white = sheet.white_cd_m2[c];
    canvas.Text(font, "white = " + FormatLabelNumber(white, 2) + " cd/m\u00b2", 11, x0 + C / 2, y + 31, kDim, Align::kCentre);
    ScaleBar bar;
    bar.bar = {x0, bar_y0, x0 + C, bar_y1};
    const ColorProcessor& view = display[c];
    bar.colour = [&view, white](double f) {
      const float l = static_cast<float>(f * white);
      const std::vector<uint8_t> q = QuantizeDisplay8(view.Apply(std::array<float, 3>{l, l, l}));
      return Rgb8{q[0], q[1], q[2]};
    };
    for (double v : NiceTicks(0.0, white, 5)) bar.ticks.push_back({v / white, FormatLabelNumber(v, 3)});
    bar.text_px = 10;
    bar.ink = kDim;
    DrawScaleBar(canvas, font, bar);
  }
  y += L::kHeaderHeight;

  // Rows.
  for (int r = 0; r < rows; ++r) {
    const int y0 = y + r * (C + L::kRowGap);
    const SkyLutDecoder& d = *skies[r].decoder;
    const double name_px = FitPx(font, skies[r].name, 14, L::kLabelWidth - 8);
    canvas.Text(font, skies[r].name, name_px, L::kMargin, y0 + C / 2, kInk);
    canvas.Text(font, fmt::format("LUT {}\u00d7{}\u00d7{}", d.width(), d.height(), d.slices()), 10, L::kMargin,
                y0 + C / 2 + 16, kDim);
    for (int c = 0; c < cols; ++c) {
      const int x0 = x_cells + c * (C + L::kColumnGap);
      const std::vector<uint8_t> px = EncodePreview8(C, C, rgb[static_cast<size_t>(r) * cols + c], display[c]);
      for (int j = 0; j < C; ++j) {
        for (int i = 0; i < C; ++i) {
          const size_t k = static_cast<size_t>(j) * C + i;
          if (inside[k]) {
            canvas.Put(x0 + i, y0 + j, {px[k * 3], px[k * 3 + 1], px[k * 3 + 2]});
          } else {
            // A thin rim just outside the horizon, so that a dark sky's disc still shows.
            const double u = 2.0 * (i + 0.5) / C - 1.0, v = 2.0 * (j + 0.5) / C - 1.0;
            if (std::sqrt(u * u + v * v) < 1.0 + 2.0 / C) canvas.Put(x0 + i, y0 + j, kRim);
          }
        }
      }
    }
  }
  sheet.png = canvas.EncodePng();
  return sheet;
}

}  // namespace skybake::lut
