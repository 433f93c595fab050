// lut-pack's contact sheet (docs/lut-pack.md, "Contact sheet"): one labelled PNG that shows what
// a game gets from a set of sky LUTs, for a person to judge.
//
//   rows     the basis skies of the set (label: name and LUT size);
//   columns  sun elevations 60, 20, 5, 0, -4 deg;
//   cell     the sky decoded from the packed texture (lut::SkyLutDecoder on the R11G11B10F texels,
//            not the float render) on an upward equidistant fisheye: zenith at the centre, the
//            horizon on the rim, the sun's azimuth to the right (lut/directions.h "fisheye"),
//            one sample per pixel at its centre;
//   display  the project's OCIO display view (color/color.h: sRGB, un-tone-mapped) with one
//            exposure per column, the same for every sky in it: white = the 99th percentile of
//            the luminance Y (cd/m^2, Y of CIE-XYZ-D65 from Linear Rec.2020 by OCIO) over the
//            column's pixels of every sky, leaving out those within 5 deg of the sun (its
//            aureole), rounded to 2 significant digits; the header states it ("white = 8200
//            cd/m²"), and a grey scale under the header, made by the same display view, has
//            ticks numbered in cd/m^2 (linear from 0 at the left to white at the right).
//
// Layout (px): margin 12, a 110 wide label column, cells of 160 x 160, 16 apart horizontally and
// 8 apart vertically, a title block of 84 and a column header of 76 above the cells:
//   width  = 2 x 12 + 110 + 5 x 160 + 4 x 16 = 998,
//   height = 2 x 12 + 84 + 76 + rows x (160 + 8) - 8.
// Deterministic: pixels are decoded independently (TBB), the percentile is taken after a sort,
// the drawing is serial (io/png_label.h).
#pragma once

#include <string>
#include <vector>

#include "color/color.h"
#include "io/png_label.h"
#include "lut/decoder.h"

namespace skybake::lut {

struct ContactSheetSky {
  std::string name;
  const SkyLutDecoder* decoder = nullptr;
};

struct ContactSheetLayout {
  static constexpr int kMargin = 12, kLabelWidth = 110, kCell = 160, kColumnGap = 16, kRowGap = 8;
  static constexpr int kTitleHeight = 84, kHeaderHeight = 76;
  static constexpr double kPercentile = 0.99;     // of Y over a column: its white
  static constexpr double kSunExclusionDeg = 5.0;  // the aureole left out of the percentile
  static int Width(int columns) { return 2 * kMargin + kLabelWidth + columns * kCell + (columns - 1) * kColumnGap; }
  static int Height(int rows) { return 2 * kMargin + kTitleHeight + kHeaderHeight + rows * (kCell + kRowGap) - kRowGap; }
};

struct ContactSheet {
  std::string png;
  int width = 0, height = 0;
  std::vector<double> sun_elevation_deg;  // the columns
  std::vector<double> white_cd_m2;        // per column: the luminance shown as display white
};

// `time_mapping_name` (e.g. "gt7-quadratic") for the title. Default columns: 60, 20, 5, 0, -4 deg.
ContactSheet RenderContactSheet(const std::vector<ContactSheetSky>& skies, const std::string& time_mapping_name,
                                const ColorConfig& config, const Font& font,
                                const std::vector<double>& sun_elevation_deg = {60, 20, 5, 0, -4});

}  // namespace skybake::lut
