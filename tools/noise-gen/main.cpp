// noise-gen: one tileable cloud noise volume (GT7 low/high frequency, Frostbite-style RGBA shape)
// from a YAML recipe, as a KTX2 3D texture, with an EXR of the float field and a PNG slice
// montage for inspection (docs/clouds.md).
//
//   noise-gen VOLUME.yaml -o VOLUME.ktx2 [--exr VOLUME.exr] [--preview VOLUME.png]
//             [--depfile VOLUME.ktx2.d]
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "io/cli.h"
#include "io/exr.h"
#include "io/fileio.h"
#include "io/png_label.h"
#include "lut/ktx2.h"
#include "noise/volume.h"
#include "preview.h"

namespace fs = std::filesystem;
using namespace skybake;
using namespace skybake::noise;

namespace {

const char* kChannelNames[4] = {"R", "G", "B", "A"};

ktx2::Format KtxFormat(VolumeFormat f) {
  switch (f) {
    case VolumeFormat::kR8Unorm: return ktx2::R8Unorm();
    case VolumeFormat::kR16Sfloat: return ktx2::R16Sfloat();
    case VolumeFormat::kR8G8B8A8Unorm: return ktx2::R8G8B8A8Unorm();
  }
  return ktx2::R8Unorm();
}

// What a channel holds, for the key/value data and the EXR.
std::string Describe(const ChannelSpec& c) {
  auto weights = [](const WorleyTerm& w) {
    std::string s;
    for (double x : w.weights) s += (s.empty() ? "" : ", ") + FormatExact(x);
    return s;
  };
  const std::string p = fmt::format("perlin fBm F={} octaves={} lacunarity={} gain={}", c.perlin.frequency, c.perlin.octaves,
                                    c.perlin.lacunarity, FormatExact(c.perlin.gain));
  const std::string w = fmt::format("inverted worley F={} lacunarity={} weights=[{}]", c.worley.frequency, c.worley.lacunarity,
                                    weights(c.worley));
  switch (c.kind) {
    case NoiseKind::kPerlin: return p;
    case NoiseKind::kWorley: return w;
    case NoiseKind::kPerlinWorley: return "perlin-worley W + P01 (1 - W) of " + p + "; " + w;
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  ToolCli cli("noise-gen",
              "Generates one tileable 3D cloud noise volume (Perlin, Worley, Perlin-Worley channels) from a YAML\n"
              "recipe and writes it as a KTX2 3D texture (R8_UNORM, R16_SFLOAT or R8G8B8A8_UNORM), optionally\n"
              "with an OpenEXR copy of the float field and a PNG slice montage. See docs/clouds.md.");
  std::string input, output, exr_path, preview_path, depfile;
  cli.app().add_option("volume", input, "Volume recipe YAML (e.g. clouds/noise_low.yaml)")->required();
  cli.app().add_option("-o,--output", output, "Output KTX2 texture")->required();
  cli.app().add_option("--exr", exr_path, "Also write the normalised float field as an OpenEXR table");
  cli.app().add_option("--preview", preview_path, "Also write a PNG montage of z slices (each tiled 2 x 2)");
  cli.app().add_option("--depfile", depfile, "Write a Make-style depfile listing every file read");
  return cli.Run(argc, argv, [&] {
    // Load and validate.
    const VolumeSpec spec = LoadVolumeSpec(input);
    std::optional<Font> font;  // the preview's labels; missing: exit 1 before any output
    if (!preview_path.empty()) font = Font::Load();
    // One core call.
    const GeneratedVolume g = GenerateVolume(spec, cli.Progress());
    const Volume& v = g.volume;
    const int n = v.resolution;

    // Encode every output in memory first: nothing is written unless all of them encode.
    Provenance prov;
    prov.tool = cli.name();
    prov.parameters = CanonicalVolumeYaml(spec);
    prov.AddInput(input);

    ktx2::Texture tex;
    tex.format = KtxFormat(spec.format);
    tex.width = tex.height = tex.depth = static_cast<uint32_t>(n);
    ktx2::SetProvenance(tex, prov);
    ktx2::SetString(tex, "KTXorientation", "rdi");
    ktx2::SetString(tex, "skybake.tile_size_m", FormatExact(spec.tile_size_m));
    ktx2::SetString(tex, "skybake.normalize", NormalizationName(spec.normalization));
    ktx2::SetString(tex, "skybake.texel_centres", "texel (i, j, k) holds the field at ((i + 1/2)/N, (j + 1/2)/N, (k + 1/2)/N) of the tile; "
                                                  "the field has period 1 on every axis (sample with REPEAT)");
    for (int c = 0; c < v.channels; ++c) {
      const std::string key = std::string("skybake.channel.") + kChannelNames[c];
      ktx2::SetString(tex, key, Describe(spec.channels[c]));
      ktx2::SetString(tex, key + ".range", FormatExact(g.range[c].first) + " " + FormatExact(g.range[c].second));
      ktx2::SetString(tex, key + ".mean", FormatExact(g.normalised[c].mean));
      ktx2::SetString(tex, key + ".stddev", FormatExact(g.normalised[c].stddev));
    }
    ktx2::SetString(tex, "skybake.encoding",
                    spec.format == VolumeFormat::kR16Sfloat ? "value = texel (binary16, round to nearest even from float32)"
                                                            : "value = texel / 255 (UNORM8, round to nearest)");
    tex.data = ktx2::EncodeTexels(tex.format, v.values);
    const std::string ktx_bytes = ktx2::EncodeKtx2(tex);

    std::string exr_bytes;
    if (!exr_path.empty()) {
      ExrTable table;
      std::vector<double> coords(n);
      for (int i = 0; i < n; ++i) coords[i] = (i + 0.5) / n * spec.tile_size_m;
      const char* axis_names[3] = {"x", "y", "z"};
      for (const char* a : axis_names) {
        table.axes.push_back({a, "m", "texel centres across one tile ((i + 1/2)/N x tile size); the field is periodic", coords});
      }
      for (int c = 0; c < v.channels; ++c) {
        table.channels.push_back(kChannelNames[c]);
        table.channel_units.push_back("1");
      }
      table.values = v.values;
      ExrImage image = TableToImage(table);
      SetProvenance(image, prov);
      for (int c = 0; c < v.channels; ++c) {
        const std::string key = std::string("skybake.channel.") + kChannelNames[c];
        image.strings[key] = Describe(spec.channels[c]);
        image.doubles[key + ".mean"] = g.normalised[c].mean;
        image.doubles[key + ".min"] = g.normalised[c].min;
        image.doubles[key + ".max"] = g.normalised[c].max;
        image.doubles[key + ".stddev"] = g.normalised[c].stddev;
      }
      image.doubles["skybake.tile_size_m"] = spec.tile_size_m;
      exr_bytes = EncodeExr(image);
    }

    std::string png_bytes;
    if (!preview_path.empty()) {
      std::vector<std::string> labels;
      for (int c = 0; c < v.channels; ++c) labels.push_back(std::string(kChannelNames[c]) + ": " + Describe(spec.channels[c]));
      const std::vector<std::string> title = {
          fmt::format("noise-gen {}: {}\u00b3 texels, {}, tile {} m, normalisation {}", fs::path(input).filename().string(), n,
                      tex.format.name, FormatExact(spec.tile_size_m), NormalizationName(spec.normalization)),
          "Four z slices per channel (columns), each repeated 2 \u00d7 2 so that a seam would show as a line through the middle.",
          "Grey = the channel's value (scale at the right of each row)."};
      png_bytes = RenderPanelSheet(VolumeMontage(v, g.range, title, labels, spec.tile_size_m), *font);
    }

    // Write.
    bool changed = WriteFileIfChanged(output, ktx_bytes);
    if (!exr_path.empty()) changed |= WriteFileIfChanged(exr_path, exr_bytes);
    if (!preview_path.empty()) changed |= WriteFileIfChanged(preview_path, png_bytes);
    if (!depfile.empty()) {
      std::vector<fs::path> deps = {input};
      if (font) deps.push_back(font->path());
      WriteDepfile(depfile, output, deps);
    }
    cli.Info(fmt::format("{} {} ({}^3 {}, {} channel{})", changed ? "wrote" : "unchanged", output, n, tex.format.name,
                         v.channels, v.channels == 1 ? "" : "s"));
  });
}
