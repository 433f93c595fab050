#include "preview.h"

#include <cmath>

#include <fmt/format.h>

#include "lut/ktx2.h"

using namespace skybake;
using namespace skybake::noise;

namespace {

std::vector<ScaleTick> UnitValueTicks() {
  std::vector<ScaleTick> t;
  for (double v : NiceTicks(0.0, 1.0, 6)) t.push_back({v, FormatLabelNumber(v, 2)});
  return t;
}

}  // namespace

PanelSheet CumulusMapPreview(const CumulusSpec& spec, const CumulusMap& map, const std::string& input_name) {
  const CumulusMapping m = spec.Mapping();
  const int n = spec.resolution;
  PanelSheet s;
  const double r_km = m.half_extent_m() / 1000.0;
  s.title_lines = {
      fmt::format("cumulus-map {}: cumulus map {}\u00d7{} at t = {} s, {} km across, north up", input_name, n, n,
                  FormatLabelNumber(spec.time_s, 6), FormatLabelNumber(2 * r_km, 4)),
      fmt::format("Texels {} km wide at the centre, {} km at the edge (sinh grid); grey = value (scale at the right).",
                  FormatLabelNumber(m.TexelSizeM(0.0) / 1000.0, 3), FormatLabelNumber(m.TexelSizeM(1.0) / 1000.0, 3))};
  s.column_headers = {"R: cloud density d\n0 = clear sky", "G: cloud type t\ncoverage layer t (L \u2212 1)"};
  s.row_labels = {"map"};
  std::vector<ScaleTick> ticks;
  for (double f : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
    const double x_m = f * m.half_extent_m();
    ticks.push_back({m.TexelCoord(x_m) / n, FormatLabelNumber(x_m / 1000.0, 3)});
  }
  s.x_axis = {"east (km) \u2192", ticks};
  s.y_axis = {"north (km) \u2192", ticks};
  s.value_ticks = {UnitValueTicks()};
  s.value_title = "value (0..1)";
  std::vector<GreyPanel> row;
  for (int p = 0; p < 2; ++p) {
    GreyPanel g{n, n, std::vector<uint8_t>(static_cast<size_t>(n) * n)};
    // North up: preview row y shows texel row n - 1 - y.
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) g.grey[static_cast<size_t>(y) * n + x] = ktx2::FloatToUnorm8(map.At(x, n - 1 - y, p));
    row.push_back(std::move(g));
  }
  s.panels = {std::move(row)};
  return s;
}

PanelSheet CoveragePreview(const CoverageSpec& spec, const CoverageTexture& t, const std::string& input_name) {
  PanelSheet s;
  s.title_lines = {
      fmt::format("cumulus-map {}: coverage texture {}\u00d7{}, {} cloud types (layers)", input_name, t.width, t.height, t.layers),
      "Per cloud type: the four channels against map density (right) and altitude (up); grey = value (scale at the right)."};
  s.column_headers = {"R: height modulation", "G: low-frequency weight", "B: mid-frequency weight", "A: ambient"};
  std::vector<ScaleTick> x_ticks, y_ticks;
  for (double d : NiceTicks(0.0, 1.0, 3)) x_ticks.push_back({d, FormatLabelNumber(d, 2)});
  const double z0 = spec.altitude_bottom_m, z1 = spec.altitude_top_m;
  if (z1 > z0) {
    for (double z : NiceTicks(z0, z1, 5)) y_ticks.push_back({(z - z0) / (z1 - z0), FormatLabelNumber(z, 4)});
  } else {
    y_ticks.push_back({0.5, FormatLabelNumber(z0, 4)});
  }
  s.x_axis = {"map density \u2192", x_ticks};
  s.y_axis = {"altitude (m) \u2192", y_ticks};
  s.value_title = "value (0..1)";
  for (int k = 0; k < t.layers; ++k) {
    s.row_labels.push_back(fmt::format("layer {}: {}", k, spec.types[k].name));
    s.value_ticks.push_back(UnitValueTicks());
    std::vector<GreyPanel> row;
    for (int c = 0; c < 4; ++c) {
      GreyPanel g{t.width, t.height, std::vector<uint8_t>(static_cast<size_t>(t.width) * t.height)};
      for (int y = 0; y < t.height; ++y)  // altitude up
        for (int x = 0; x < t.width; ++x) g.grey[static_cast<size_t>(y) * t.width + x] = ktx2::FloatToUnorm8(t.At(k, x, t.height - 1 - y, c));
      row.push_back(std::move(g));
    }
    s.panels.push_back(std::move(row));
  }
  return s;
}
