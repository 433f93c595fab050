// fuzz_seeds OUT_DIR: the binary seeds of the fuzz targets, written by the core's own encoders
// (the text seeds are the repository's YAML and CSV files; bench/fuzz copies both):
//   OUT_DIR/exr/   a one-axis and a three-axis table (single part) and a two-part file
//   OUT_DIR/ktx2/  R8 3D, RGBA16F 2D, B10G11R11 2D array and RGBA32F 1D textures
//   OUT_DIR/dds/   R11G11B10F 2D, 2D array and 3D textures
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "io/exr.h"
#include "lut/dds.h"
#include "lut/ktx2.h"

using namespace skybake;

namespace {
void Write(const std::filesystem::path& p, const std::string& bytes) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

ExrTable Table(size_t n0, size_t n1, size_t n2, size_t channels) {
  ExrTable t;
  const size_t n[3] = {n0, n1, n2};
  for (size_t a = 0; a < 3; ++a) {
    if (n[a] == 0) break;
    ExrAxis axis{"axis" + std::to_string(a), "m", "seed axis", {}};
    for (size_t i = 0; i < n[a]; ++i) axis.values.push_back(static_cast<double>(i) * 0.5);
    t.axes.push_back(axis);
  }
  for (size_t c = 0; c < channels; ++c) {
    t.channels.push_back("c" + std::to_string(c));
    t.channel_units.push_back("1");
  }
  t.values.resize(t.Count() * channels);
  for (size_t i = 0; i < t.values.size(); ++i) t.values[i] = static_cast<float>(i % 17) * 0.25f;
  return t;
}

ktx2::Texture Ktx(ktx2::Format f, uint32_t w, uint32_t h, uint32_t d, uint32_t layers) {
  ktx2::Texture t;
  t.format = f;
  t.width = w;
  t.height = h;
  t.depth = d;
  t.layers = layers;
  t.writer = "skybake fuzz_seeds";
  ktx2::SetString(t, "skybake.seed", "1");
  t.data.assign(t.ExpectedDataBytes(), '\0');
  for (size_t i = 0; i < t.data.size(); ++i) t.data[i] = static_cast<char>((i * 7) % 61);
  return t;
}

dds::Texture Dds(uint32_t w, uint32_t h, uint32_t d, uint32_t layers) {
  dds::Texture t;
  t.width = w;
  t.height = h;
  t.depth = d;
  t.array_size = layers;
  t.data.assign(t.ExpectedDataBytes(), '\0');
  for (size_t i = 0; i < t.data.size(); ++i) t.data[i] = static_cast<char>((i * 5) % 53);
  return t;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds OUT_DIR\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  Write(out / "exr" / "table1.exr", EncodeExr(TableToImage(Table(16, 0, 0, 2))));
  Write(out / "exr" / "table3.exr", EncodeExr(TableToImage(Table(4, 3, 2, 3))));
  Write(out / "exr" / "parts.exr",
        EncodeExrParts({{"a", TableToImage(Table(8, 0, 0, 1))}, {"b", TableToImage(Table(3, 2, 0, 4))}}));
  Write(out / "ktx2" / "r8_3d.ktx2", ktx2::EncodeKtx2(Ktx(ktx2::R8Unorm(), 4, 4, 4, 0)));
  Write(out / "ktx2" / "rgba16f_2d.ktx2", ktx2::EncodeKtx2(Ktx(ktx2::R16G16B16A16Sfloat(), 4, 2, 0, 0)));
  Write(out / "ktx2" / "b10g11r11_array.ktx2", ktx2::EncodeKtx2(Ktx(ktx2::B10G11R11UfloatPack32(), 4, 2, 0, 3)));
  Write(out / "ktx2" / "rgba32f_1d.ktx2", ktx2::EncodeKtx2(Ktx(ktx2::R32G32B32A32Sfloat(), 8, 0, 0, 0)));
  Write(out / "dds" / "r11g11b10_2d.dds", dds::EncodeDds(Dds(4, 4, 0, 1)));
  Write(out / "dds" / "r11g11b10_array.dds", dds::EncodeDds(Dds(4, 2, 0, 3)));
  Write(out / "dds" / "r11g11b10_3d.dds", dds::EncodeDds(Dds(4, 4, 4, 1)));
  return 0;
}
