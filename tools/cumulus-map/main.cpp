// cumulus-map: the cumulus map (cloud density + cloud type over 240 km, more texels at the
// centre, advected by the wind) or the coverage texture (per cloud type: density x altitude ->
// height modulation, low/mid-frequency weights, ambient), as KTX2 with optional EXR and PNG
// (docs/clouds.md).
//
//   cumulus-map CUMULUS.yaml -o map.ktx2 [--time-s T] [--exr map.exr] [--preview map.png]
//   cumulus-map --product coverage COVERAGE.yaml -o coverage.ktx2 [--exr ...] [--preview ...]
#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "io/cli.h"
#include "io/error.h"
#include "io/exr.h"
#include "io/fileio.h"
#include "io/png_label.h"
#include "lut/ktx2.h"
#include "noise/coverage.h"
#include "noise/cumulus.h"
#include "preview.h"

namespace fs = std::filesystem;
using namespace skybake;
using namespace skybake::noise;

namespace {

struct Encoded {
  std::string ktx, exr, png;
  std::string summary;
};

Encoded MapProduct(ToolCli& cli, const std::string& input, std::optional<double> time_override, const Font* font) {
  CumulusSpec spec = LoadCumulusSpec(input);
  if (time_override) spec.time_s = *time_override;
  const WeatherField field(spec.weather);
  const CumulusMap map = GenerateCumulusMap(spec, field, cli.Progress());
  const CumulusMapping m = spec.Mapping();
  const int n = spec.resolution;

  Provenance prov;
  prov.tool = cli.name();
  prov.parameters = CanonicalCumulusYaml(spec);
  prov.AddInput(input);

  Encoded e;
  ktx2::Texture tex;
  tex.format = ktx2::R8G8Unorm();
  tex.width = tex.height = static_cast<uint32_t>(n);
  ktx2::SetProvenance(tex, prov);
  ktx2::SetString(tex, "KTXorientation", "ru");  // row 0 is the southern edge: T increases upwards (north)
  ktx2::SetString(tex, "skybake.channels", "R: cloud density d in [0, 1] (0 = clear); G: cloud type t in [0, 1] "
                                           "(coverage texture layer t (L - 1))");
  ktx2::SetString(tex, "skybake.mapping",
                  "per axis: x = R sinh(a u) / sinh(a), u = asinh(x sinh(a) / R) / a, u = 2 (i + 1/2) / N - 1 at texel "
                  "centres; x east, y north, metres from the world centre");
  ktx2::SetString(tex, "skybake.mapping.half_extent_m", FormatExact(m.half_extent_m()));
  ktx2::SetString(tex, "skybake.mapping.a", FormatExact(m.a()));
  ktx2::SetString(tex, "skybake.texel_size_m.centre", FormatExact(m.TexelSizeM(0.0)));
  ktx2::SetString(tex, "skybake.texel_size_m.edge", FormatExact(m.TexelSizeM(1.0)));
  ktx2::SetString(tex, "skybake.time_s", FormatExact(spec.time_s));
  ktx2::SetString(tex, "skybake.wind_m_s", FormatExact(spec.wind_m_s[0]) + " " + FormatExact(spec.wind_m_s[1]));
  ktx2::SetString(tex, "skybake.encoding", "value = texel / 255 (UNORM8, round to nearest)");
  tex.data = ktx2::EncodeTexels(tex.format, map.values);
  e.ktx = ktx2::EncodeKtx2(tex);

  ExrTable table;
  std::vector<double> world(n);
  for (int i = 0; i < n; ++i) world[i] = m.WorldFromU(m.TexelCentreU(i));
  table.axes.push_back({"x", "m", "east of the world centre at texel centres (sinh grid, denser at the centre)", world});
  table.axes.push_back({"y", "m", "north of the world centre at texel centres (sinh grid, denser at the centre)", world});
  table.channels = {"density", "type"};
  table.channel_units = {"1", "1"};
  table.values = map.values;
  ExrImage image = TableToImage(table);
  SetProvenance(image, prov);
  image.doubles["skybake.time_s"] = spec.time_s;
  image.doubles["skybake.texel_size_m.centre"] = m.TexelSizeM(0.0);
  image.doubles["skybake.texel_size_m.edge"] = m.TexelSizeM(1.0);
  e.exr = EncodeExr(image);
  if (font) e.png = RenderPanelSheet(CumulusMapPreview(spec, map, fs::path(input).filename().string()), *font);
  e.summary = fmt::format("{}x{} R8G8_UNORM at t = {} s", n, n, FormatExact(spec.time_s));
  return e;
}

Encoded CoverageProduct(ToolCli& cli, const std::string& input, const Font* font) {
  const CoverageSpec spec = LoadCoverageSpec(input);
  const CoverageTexture t = BuildCoverageTexture(spec);

  Provenance prov;
  prov.tool = cli.name();
  prov.parameters = CanonicalCoverageYaml(spec);
  prov.AddInput(input);
  std::string layers;
  for (size_t l = 0; l < spec.types.size(); ++l) layers += (l ? " " : "") + spec.types[l].name;

  Encoded e;
  ktx2::Texture tex;
  tex.format = ktx2::R8G8B8A8Unorm();
  tex.width = static_cast<uint32_t>(t.width);
  tex.height = static_cast<uint32_t>(t.height);
  tex.layers = static_cast<uint32_t>(t.layers);
  ktx2::SetProvenance(tex, prov);
  ktx2::SetString(tex, "KTXorientation", "ru");  // row 0 is the lowest altitude
  ktx2::SetString(tex, "skybake.channels", "R: height modulation; G: low-frequency weight; B: mid-frequency weight; A: ambient");
  ktx2::SetString(tex, "skybake.layers", layers);
  ktx2::SetString(tex, "skybake.density_axis", "column i holds map density i / (W - 1); sample u = (d (W - 1) + 1/2) / W");
  ktx2::SetString(tex, "skybake.altitude_axis_m", FormatExact(spec.altitude_bottom_m) + " " + FormatExact(spec.altitude_top_m));
  ktx2::SetString(tex, "skybake.altitude_axis",
                  "row j holds altitude bottom + j (top - bottom) / (H - 1); sample v = ((z - bottom)/(top - bottom) (H - 1) + 1/2) / H");
  ktx2::SetString(tex, "skybake.encoding", "value = texel / 255 (UNORM8, round to nearest)");
  tex.data = ktx2::EncodeTexels(tex.format, t.values);
  e.ktx = ktx2::EncodeKtx2(tex);

  ExrTable table;
  std::vector<double> d(t.width), z(t.height), l(t.layers);
  for (int i = 0; i < t.width; ++i) d[i] = spec.ColumnDensity(i);
  for (int j = 0; j < t.height; ++j) z[j] = spec.RowAltitudeM(j);
  for (int k = 0; k < t.layers; ++k) l[k] = k;
  table.axes.push_back({"density", "1", "cumulus map density", d});
  table.axes.push_back({"altitude", "m", "altitude above the ground", z});
  table.axes.push_back({"type", "1", "cloud type index (layer): " + layers, l});
  table.channels = {"height_modulation", "low_frequency", "mid_frequency", "ambient"};
  table.channel_units = {"1", "1", "1", "1"};
  table.values = t.values;
  ExrImage image = TableToImage(table);
  SetProvenance(image, prov);
  e.exr = EncodeExr(image);
  if (font) e.png = RenderPanelSheet(CoveragePreview(spec, t, fs::path(input).filename().string()), *font);
  e.summary = fmt::format("{}x{} x{} layers R8G8B8A8_UNORM ({})", t.width, t.height, t.layers, layers);
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("cumulus-map",
              "Writes the cumulus map (cloud density and type over the world, denser texels at the centre,\n"
              "advected by the wind) or, with --product coverage, the coverage texture (per cloud type: map\n"
              "density x altitude -> height modulation, noise weights, ambient) as KTX2. See docs/clouds.md.");
  std::string input, output, exr_path, preview_path, depfile, product = "map";
  std::optional<double> time_s;
  cli.app().add_option("input", input, "clouds/cumulus.yaml (map) or clouds/coverage.yaml (coverage)")->required();
  cli.app().add_option("-o,--output", output, "Output KTX2 texture")->required();
  cli.app().add_option("--product", product, "map (default) or coverage")->check(CLI::IsMember({"map", "coverage"}));
  cli.app().add_option("--time-s", time_s, "Map time in s (overrides time_s of the YAML); the map samples the weather at x - wind t");
  cli.app().add_option("--exr", exr_path, "Also write the float values as an OpenEXR table");
  cli.app().add_option("--preview", preview_path, "Also write a PNG preview (north / altitude up)");
  cli.app().add_option("--depfile", depfile, "Write a Make-style depfile listing every file read");
  return cli.Run(argc, argv, [&] {
    if (product == "coverage" && time_s) throw UsageError("--time-s applies to --product map only");
    if (time_s && !(std::abs(*time_s) <= kMaxAbsTimeS)) {
      throw UsageError(fmt::format("--time-s {}: expected a time in [-1e7, 1e7] s", FormatExact(*time_s)));
    }
    // Load, validate, compute and encode every output in memory; write only when all succeeded.
    std::optional<Font> font;  // the preview's labels; missing: exit 1 before any output
    if (!preview_path.empty()) font = Font::Load();
    const Font* f = font ? &*font : nullptr;
    const Encoded e = product == "map" ? MapProduct(cli, input, time_s, f) : CoverageProduct(cli, input, f);
    bool changed = WriteFileIfChanged(output, e.ktx);
    if (!exr_path.empty()) changed |= WriteFileIfChanged(exr_path, e.exr);
    if (!preview_path.empty()) changed |= WriteFileIfChanged(preview_path, e.png);
    if (!depfile.empty()) {
      std::vector<fs::path> deps = {input};
      if (font) deps.push_back(font->path());
      WriteDepfile(depfile, output, deps);
    }
    cli.Info(fmt::format("{} {} ({})", changed ? "wrote" : "unchanged", output, e.summary));
  });
}
