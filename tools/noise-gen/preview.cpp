#include "preview.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

using skybake::FormatLabelNumber;

namespace {
std::string Metres(double m) { return std::fabs(m) >= 1000.0 ? FormatLabelNumber(m / 1000.0, 3) + " km" : FormatLabelNumber(m, 3) + " m"; }
}  // namespace

skybake::PanelSheet VolumeMontage(const skybake::noise::Volume& v, const std::vector<std::pair<double, double>>& range,
                                  const std::vector<std::string>& title_lines, const std::vector<std::string>& channel_labels,
                                  double tile_size_m) {
  constexpr int kSlices = 4;
  const int n = v.resolution, panel = 2 * n;
  skybake::PanelSheet sheet;
  sheet.title_lines = title_lines;
  sheet.row_labels = channel_labels;
  sheet.zoom = n < 64 ? 2 : 1;
  for (int s = 0; s < kSlices; ++s) {
    const int k = s * n / kSlices;
    sheet.column_headers.push_back(fmt::format("z slice k = {}", k) + "\nz = " + Metres((k + 0.5) / n * tile_size_m));
  }
  sheet.x_axis = {"x (2 tiles) \u2192", {{0.0, "0"}, {0.5, Metres(tile_size_m)}, {1.0, Metres(2 * tile_size_m)}}};
  sheet.y_axis = {"y, downwards (2 tiles)", {{1.0, "0"}, {0.5, Metres(tile_size_m)}, {0.0, Metres(2 * tile_size_m)}}};
  sheet.value_title = "channel value";
  for (int c = 0; c < v.channels; ++c) {
    const double lo = range[c].first, hi = range[c].second;
    std::vector<skybake::ScaleTick> ticks;
    if (hi > lo) {
      for (double t : skybake::NiceTicks(lo, hi, 6)) ticks.push_back({(t - lo) / (hi - lo), FormatLabelNumber(t, 3)});
    }
    sheet.value_ticks.push_back(std::move(ticks));
    const double scale = hi > lo ? 255.0 / (hi - lo) : 0.0;
    std::vector<skybake::GreyPanel> row;
    for (int s = 0; s < kSlices; ++s) {
      const int k = s * n / kSlices;
      skybake::GreyPanel p{panel, panel, std::vector<uint8_t>(static_cast<size_t>(panel) * panel)};
      for (int y = 0; y < panel; ++y) {
        for (int x = 0; x < panel; ++x) {
          const double value = v.At(x % n, y % n, k, c);
          const double g = std::clamp((value - lo) * scale, 0.0, 255.0);
          p.grey[static_cast<size_t>(y) * panel + x] = static_cast<uint8_t>(std::floor(g + 0.5));
        }
      }
      row.push_back(std::move(p));
    }
    sheet.panels.push_back(std::move(row));
  }
  return sheet;
}
