// ocio/config.ocio and the OCIO-based conversions: ociocheck, the published checked values of
// the transforms, round trips, the XYZ convention of each observer, previews and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "color/color.h"
#include "color/ocio_config.h"
#include "io/fileio.h"
#include "io/png.h"
#include "spectrum/cmf.h"
#include "spectrum/xyz.h"
#include "support/threads.h"

using namespace skybake;
namespace fs = std::filesystem;

namespace {
const std::string kSource = SKYBAKE_SOURCE_DIR;
fs::path ConfigPath() { return fs::path(kSource) / "ocio/config.ocio"; }
const ColorConfig& Config() {
  static const ColorConfig c = ColorConfig::Load(ConfigPath());
  return c;
}
std::string DataFile(const std::string& name) { return kSource + "/atmospheres/data/" + name; }
const Cmf& LoadedCmf(Observer o) {
  static const Cmf k2006 = Cmf::Load(DataFile(CmfFileName(Observer::kCie2006_2deg)), Observer::kCie2006_2deg);
  static const Cmf k1931 = Cmf::Load(DataFile(CmfFileName(Observer::kCie1931_2deg)), Observer::kCie1931_2deg);
  return o == Observer::kCie2006_2deg ? k2006 : k1931;
}
std::string Message(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

// `ociocheck --iconfig ocio/config.ocio` (opencolorio-tools, installed by scripts/setup) must
// accept the config (exit 0). The test fails, rather than skips, when ociocheck is absent.
TEST(OcioConfig, OciocheckAcceptsTheConfig) {
  std::string found;
  const char* path_env = std::getenv("PATH");
  std::string path = path_env ? path_env : "/usr/bin";
  for (size_t b = 0; b <= path.size();) {
    size_t e = path.find(':', b);
    if (e == std::string::npos) e = path.size();
    fs::path cand = fs::path(path.substr(b, e - b)) / "ociocheck";
    if (!path.substr(b, e - b).empty() && fs::exists(cand)) {
      found = cand.string();
      break;
    }
    b = e + 1;
  }
  ASSERT_FALSE(found.empty()) << "ociocheck not found on PATH: scripts/setup installs opencolorio-tools";
  const std::string cmd = "'" + found + "' --iconfig '" + ConfigPath().string() + "' > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << cmd;
}

// The checked-in config holds what the generator builds from today's data tables: the CIE 2006
// diagonal read back through OCIO equals the recomputed one (to float precision).
TEST(OcioConfig, Cie2006MappingMatchesTheDataTables) {
  TabulatedSpectrum d65 = LoadSpectrumColumn(DataFile("cie_d65_1nm.csv"), "relative_spd");
  OcioConfigBuild build = BuildOcioConfig(LoadedCmf(Observer::kCie2006_2deg), d65, "");
  ColorProcessor p = Config().Converter(ocio_names::kCie2006Xyz, ocio_names::kCieXyzD65);
  std::array<float, 3> x = p.Apply({1.0f, 0.0f, 0.0f}), y = p.Apply({0.0f, 1.0f, 0.0f}), z = p.Apply({0.0f, 0.0f, 1.0f});
  EXPECT_NEAR(x[0], build.cie2006_to_reference[0], 1e-6);
  EXPECT_EQ(y[1], 1.0f);  // Y (luminance) unchanged
  EXPECT_NEAR(z[2], build.cie2006_to_reference[2], 1e-6);
  EXPECT_EQ(x[1], 0.0f);
  EXPECT_EQ(z[0], 0.0f);
  // D65 under CIE 2006 (computed, docs/color.md §3.3): XYZ/Y = (0.94755356, 1, 1.07540434).
  EXPECT_NEAR(build.d65_cie2006.X, 0.94755356, 1e-8);
  EXPECT_NEAR(build.d65_cie2006.Z, 1.07540434, 1e-8);
}

// Checked values (computed with OCIO 2.1.2 on Debian
// 12): Rec.2020 (1,1,1) -> XYZ (0.950456, 1, 1.08906), i.e. the D65 white xy (0.3127, 0.3290);
// Rec.2020 red -> (0.636958, 0.2627, 0) (ITU-R BT.2100 Table 4 Y coefficient 0.2627).
TEST(OcioConfig, Rec2020ToXyzCheckedValues) {
  ColorProcessor p = Config().Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  std::array<float, 3> w = p.Apply({1, 1, 1});
  EXPECT_NEAR(w[0], 0.950456, 1e-6);
  EXPECT_NEAR(w[1], 1.0, 1e-6);
  EXPECT_NEAR(w[2], 1.08906, 1e-5);
  std::array<float, 3> r = p.Apply({1, 0, 0});
  EXPECT_NEAR(r[0], 0.636958, 1e-6);
  EXPECT_NEAR(r[1], 0.2627, 1e-6);
  EXPECT_EQ(r[2], 0.0f);
  // Rec.709 (1,1,1) is the same white.
  std::array<float, 3> w709 = Config().Converter(ocio_names::kLinearRec709, ocio_names::kCieXyzD65).Apply({1, 1, 1});
  EXPECT_NEAR(w709[0], 0.950456, 1e-6);
  EXPECT_NEAR(w709[2], 1.08906, 1e-5);
}

// Display encodings (checked values, notes §2.2): linear Rec.709 0.18 -> sRGB 0.461356 (IEC
// 61966-2-1: 1.055·0.18^(1/2.4) - 0.055); 1.0 -> Rec.2100-PQ 0.508078 with 1.0 = 100 cd/m²
// (SMPTE ST 2084 at 100 cd/m²). The exposure scale enters as documented: 0.09 at +1 stop is 0.18;
// 100 cd/m² with white_cd_m2 = 100 on PQ is 100 cd/m².
TEST(OcioConfig, DisplayCheckedValuesAndExposure) {
  ColorProcessor srgb = Config().Display(ocio_names::kLinearRec709, DisplayView{});
  std::array<float, 3> g = srgb.Apply({0.18f, 0.18f, 0.18f});
  EXPECT_NEAR(g[0], 0.461356, 2e-6);
  EXPECT_NEAR(g[1], 0.461356, 2e-6);
  EXPECT_NEAR(1.055 * std::pow(0.18, 1 / 2.4) - 0.055, 0.461356, 1e-6);
  ColorProcessor plus1 = Config().Display(ocio_names::kLinearRec709, DisplayView{.exposure_stops = 1.0});
  EXPECT_NEAR(plus1.Apply({0.09f, 0.09f, 0.09f})[0], 0.461356, 2e-6);

  DisplayView pq{.display = ocio_names::kDisplayRec2100Pq};
  EXPECT_NEAR(Config().Display(ocio_names::kLinearRec709, pq).Apply({1, 1, 1})[1], 0.508078, 2e-6);
  DisplayView pq_abs{.display = ocio_names::kDisplayRec2100Pq, .white_cd_m2 = 100.0};
  EXPECT_NEAR(Config().Display(ocio_names::kLinearRec709, pq_abs).Apply({100, 100, 100})[1], 0.508078, 2e-6);
  // The same absolute luminance given as XYZ (Y = 100 cd/m², D65 white) lands on the same code.
  std::array<float, 3> xyz_white{0.9504559f * 100, 100.0f, 1.0890578f * 100};
  std::array<float, 3> code = Config().Display(ocio_names::kCieXyzD65, pq_abs).Apply(xyz_white);
  for (float c : code) EXPECT_NEAR(c, 0.508078, 5e-6);
  const DisplayView dim{.white_cd_m2 = 8000, .exposure_stops = -1};
  EXPECT_NEAR(dim.Scale(), 1.0 / 16000.0, 1e-18);
}

// XYZ -> Linear Rec.2020 -> XYZ returns every value within 1e-5 (relative for large values):
// 2000 random XYZ inside a box that contains the spectral locus, and absolute sky luminances.
TEST(OcioConfig, XyzRec2020RoundTrip) {
  ColorProcessor to = Config().Converter(ocio_names::kCieXyzD65, ocio_names::kLinearRec2020);
  ColorProcessor back = Config().Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> xyz;
  for (int i = 0; i < 2000; ++i) {
    const float scale = i < 1000 ? 1.0f : 1e4f;  // relative and absolute (cd/m²) magnitudes
    xyz.insert(xyz.end(), {scale * 1.1f * u(rng), scale * u(rng), scale * 1.8f * u(rng)});
  }
  std::vector<float> v = xyz;
  to.Apply(v);
  back.Apply(v);
  for (size_t i = 0; i < v.size(); ++i) {
    const double mag = i < 3000 ? 1.0 : 1e4;
    EXPECT_NEAR(v[i], xyz[i], 1e-5 * mag) << i;
  }
}

// The XYZ convention (docs/color.md §6): the CIE D65 spectrum, integrated with either observer
// and converted through OCIO from XyzColorSpace(observer), is neutral in Linear Rec.2020:
//  - CIE 2006 2°: neutral by construction of "CIE 2006 2deg XYZ", within float precision (2e-6);
//  - CIE 1931 2°: D65's xy (0.312727, 0.329023) vs the encodings' (0.3127, 0.3290) leaves
//    (1.00013, 1.00004, 0.99983)·k: within 2.5e-4.
// Y is luminance in cd/m²: D65 scaled to 1 W m^-2 sr^-1 nm^-1 at 560 nm has Y = 683·Σ ȳ S/100.
TEST(OcioConfig, D65SpectrumIsNeutralInRec2020) {
  TabulatedSpectrum d65 = LoadSpectrumColumn(DataFile("cie_d65_1nm.csv"), "relative_spd");
  WavelengthGrid g = WavelengthGrid::Uniform(360, 830, 1);
  Spectrum s = Resample(d65, g);
  for (double& v : s.values) v /= 100.0;  // S(560 nm) = 1 W m^-2 sr^-1 nm^-1
  for (auto [obs, tol] : {std::pair{Observer::kCie2006_2deg, 2e-6}, {Observer::kCie1931_2deg, 2.5e-4}}) {
    XyzWeights w(g, LoadedCmf(obs));
    Xyz xyz = SpectrumToXyz(w, s);
    std::array<float, 3> rgb = Config()
                                   .Converter(XyzColorSpace(obs), ocio_names::kLinearRec2020)
                                   .Apply({static_cast<float>(xyz.X), static_cast<float>(xyz.Y), static_cast<float>(xyz.Z)});
    const double mean = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
    for (float c : rgb) EXPECT_NEAR(c / mean, 1.0, tol) << ObserverName(obs);
    // Neutral RGB in Rec.2020 has R = G = B = Y.
    EXPECT_NEAR(mean / xyz.Y, 1.0, tol) << ObserverName(obs);
  }
}

// Equal-energy light is not white on a D65 display: x = y = 1/3 is pinkish relative to D65
// (more red than blue), for both observers; the 2006 mapping leaves Y unchanged.
TEST(OcioConfig, EqualEnergyIsWarmerThanD65AndYIsKept) {
  for (Observer obs : {Observer::kCie2006_2deg, Observer::kCie1931_2deg}) {
    WavelengthGrid g = WavelengthGrid::Uniform(360, 830, 5);
    Xyz e = XyzWeights(g, LoadedCmf(obs)).Integrate(std::vector<double>(g.size(), 1e-3));
    std::array<float, 3> in{static_cast<float>(e.X), static_cast<float>(e.Y), static_cast<float>(e.Z)};
    std::array<float, 3> rgb = Config().Converter(XyzColorSpace(obs), ocio_names::kLinearRec2020).Apply(in);
    EXPECT_GT(rgb[0], rgb[2] * 1.05f) << ObserverName(obs);
    std::array<float, 3> ref = Config().Converter(XyzColorSpace(obs), ocio_names::kCieXyzD65).Apply(in);
    EXPECT_NEAR(ref[1], in[1], 1e-6 * in[1]) << ObserverName(obs);
  }
}

// Previews: 8-bit PNG through the display view, decoded back; quantisation as documented;
// identical bytes at 1 and 2 threads and on a second write.
TEST(Preview, PngThroughDisplayView) {
  const int w = 300, h = 200;  // 60000 pixels: several parallel chunks
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
      p[0] = 1000.0f * x / (w - 1);  // cd/m²-like values; white at 1000 (white_cd_m2)
      p[1] = 180.0f;                 // 0.18 of white -> sRGB 0.461356 -> 118
      p[2] = 1000.0f * y / (h - 1);
    }
  }
  ColorProcessor view = Config().Display(ocio_names::kLinearRec709, DisplayView{.white_cd_m2 = 1000.0});
  const fs::path out = fs::path(::testing::TempDir()) / "skybake_preview_test.png";
  const std::string bytes1 = test::WithThreads(1, [&] {
    WritePreviewPng(out, w, h, rgb, view);
    return ReadFileBytes(out);
  });
  const std::string bytes2 = test::WithThreads(2, [&] { return EncodePng8(w, h, 3, EncodePreview8(w, h, rgb, view)); });
  EXPECT_EQ(bytes1, bytes2);
  EXPECT_FALSE(WritePreviewPng(out, w, h, rgb, view));  // unchanged content: not rewritten
  int dw = 0, dh = 0, dc = 0;
  std::vector<uint8_t> px = DecodePng8(bytes1, out.string(), &dw, &dh, &dc);
  ASSERT_EQ(dw, w);
  ASSERT_EQ(dh, h);
  ASSERT_EQ(dc, 3);
  EXPECT_EQ(px[1], 118);                                     // G everywhere: round(0.461356·255)
  EXPECT_EQ(px[0], 0);                                       // R at x = 0
  EXPECT_EQ(px[(static_cast<size_t>(w) - 1) * 3], 255);       // R at x = w-1: white
  EXPECT_EQ(px[(static_cast<size_t>(h - 1) * w) * 3 + 2], 255);  // B at the bottom row
}

TEST(Preview, Quantisation) {
  std::vector<float> v{0.0f, 1.0f, 0.5f, -1.0f, 2.0f, std::nanf(""), 0.461356f, 1.0f / 255.0f};
  EXPECT_EQ(QuantizeDisplay8(v), (std::vector<uint8_t>{0, 255, 128, 0, 255, 0, 118, 1}));
}

// Processors are immutable: applying one from many threads at once gives the single-thread bits.
TEST(Preview, ParallelApplyIsDeterministic) {
  ColorProcessor p = Config().Converter(ocio_names::kCie2006Xyz, ocio_names::kLinearRec2020);
  std::vector<float> a(3 * 200000);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 5000.0f);
  for (float& v : a) v = u(rng);
  std::vector<float> serial = a, parallel = a;
  test::WithThreads(1, [&] { p.Apply(serial); });
  test::WithThreads(4, [&] { p.Apply(parallel); });
  EXPECT_EQ(serial, parallel);
}

TEST(ColorConfig, ErrorsNameTheProblem) {
  EXPECT_EQ(Message([] { Config().Converter("Linear Rec.2021", ocio_names::kLinearRec2020); }),
            ConfigPath().string() +
                ": no colour space 'Linear Rec.2021' in the OCIO config (it has 'sRGB - Display', 'Rec.1886 Rec.709 - "
                "Display', 'Rec.2100-PQ - Display', 'CIE-XYZ-D65', 'Linear Rec.2020', 'Linear Rec.709 (sRGB)', 'CIE "
                "2006 2deg XYZ', 'ACES2065-1', 'Raw')");
  EXPECT_EQ(Message([] { Config().Display(ocio_names::kRaw, DisplayView{}); }),
            ConfigPath().string() + ": a preview needs a scene-referred colour space, not 'Raw'");
  EXPECT_EQ(Message([] { Config().Display(ocio_names::kLinearRec2020, DisplayView{.display = "P3"}); }),
            ConfigPath().string() + ": no display 'P3' in the OCIO config (it has 'sRGB', 'Rec.1886 Rec.709', 'Rec.2100-PQ')");
  EXPECT_EQ(Message([] { Config().Display(ocio_names::kLinearRec2020, DisplayView{.white_cd_m2 = 0.0}); }),
            ConfigPath().string() + ": preview exposure: 2^0 / 0 cd/m2 is not a positive scale");
  EXPECT_EQ(Message([] { ColorConfig::Load("/nonexistent/config.ocio"); }),
            "/nonexistent/config.ocio: cannot read the OCIO config (given with --ocio-config)");
  const fs::path bad = fs::path(::testing::TempDir()) / "skybake_bad_config.ocio";
  WriteFileIfChanged(bad, "ocio_profile_version: 2.1\nroles: {reference: nothing}\n");
  EXPECT_EQ(Message([&] { ColorConfig::Load(bad); }).rfind(bad.string() + ": invalid OCIO config: ", 0), 0u);
}

// Path resolution: explicit path, then $SKYBAKE_OCIO, then the repository's ocio/config.ocio
// found upwards from the test executable (build/<x>/bin inside the repository).
TEST(ColorConfig, PathResolution) {
  EXPECT_EQ(ColorConfig::ResolvePath(ConfigPath()), ConfigPath());
  ::unsetenv("SKYBAKE_OCIO");
  EXPECT_EQ(fs::weakly_canonical(ColorConfig::ResolvePath()), fs::weakly_canonical(ConfigPath()));
  ::setenv("SKYBAKE_OCIO", "/nonexistent/env.ocio", 1);
  EXPECT_EQ(Message([] { ColorConfig::ResolvePath(); }),
            "/nonexistent/env.ocio: cannot read the OCIO config (named by $SKYBAKE_OCIO)");
  ::unsetenv("SKYBAKE_OCIO");
}

// The renderer's path of docs/color.md §9, end to end: spectral radiance on a 5 nm grid -> XYZ
// (CIE 2006 weights) -> Linear Rec.2020 through OCIO -> sRGB preview. Pixel 0 is D65 light
// (neutral: R = G = B in the PNG), pixel 1 is a 5778 K blackbody scaled to the same luminance
// (warmer than D65: R > B); with white_cd_m2 = 2·Y both sit mid-grey-ish, below clipping.
TEST(Preview, RendererPathEndToEnd) {
  const WavelengthGrid grid = WavelengthGrid::Uniform(360, 825, 5);  // D65 is tabulated to 830 nm
  const XyzWeights w(grid, LoadedCmf(kDefaultObserver));
  Spectrum d65 = Resample(LoadSpectrumColumn(DataFile("cie_d65_1nm.csv"), "relative_spd"), grid);
  std::vector<double> sun(grid.size());
  for (size_t i = 0; i < grid.size(); ++i) {
    const double l = grid[i] * 1e-9, h = 6.62607015e-34, c = 2.99792458e8, kb = 1.380649e-23;
    sun[i] = 2 * h * c * c / std::pow(l, 5) / std::expm1(h * c / (l * kb * 5778.0)) * 1e-9;
  }
  const Xyz a = w.Integrate(d65.values);
  Xyz b = w.Integrate(sun);
  const double s = a.Y / b.Y;
  b = Xyz{b.X * s, b.Y * s, b.Z * s};
  std::vector<float> pixels{static_cast<float>(a.X), static_cast<float>(a.Y), static_cast<float>(a.Z),
                            static_cast<float>(b.X), static_cast<float>(b.Y), static_cast<float>(b.Z)};
  Config().Converter(XyzColorSpace(w.observer()), ocio_names::kLinearRec2020).Apply(pixels);
  const fs::path png = fs::path(::testing::TempDir()) / "skybake_renderer_path.png";
  WritePreviewPng(png, 2, 1, pixels, Config().Display(ocio_names::kLinearRec2020, {.white_cd_m2 = 2.0 * a.Y}));
  int pw = 0, ph = 0, pc = 0;
  std::vector<uint8_t> px = DecodePng8(ReadFileBytes(png), png.string(), &pw, &ph, &pc);
  ASSERT_EQ(px.size(), 6u);
  // Neutral within one code: on the 5 nm grid D65 is neutral to ~5e-5 in chromaticity (exactly
  // only with the 1 nm sums of the config's mapping), and 0.7354·255 = 187.5 sits on a rounding edge.
  EXPECT_NEAR(px[0], px[1], 1);
  EXPECT_NEAR(px[1], px[2], 1);
  EXPECT_NEAR(px[1], 188, 1);  // Y = white/2 -> sRGB code 0.7354 -> 187.5 (IEC 61966-2-1)
  EXPECT_GT(px[3], px[5] + 5);
}

// The exposure is exact whatever its size: c·k through the view equals c through the view at
// k = 1, for white_cd_m2 from 1e-3 to 1e9 cd/m² (absolute skies and the sun need k down to
// 1e-9). OCIO 2.1.2 loses such small scales when it composes matrices, so color.h applies k
// itself; this guards that.
TEST(Preview, ExposureIsExactOverManyStops) {
  const std::array<float, 3> c{0.2f, 0.5f, 0.05f};
  const std::array<float, 3> ref = Config().Display(ocio_names::kLinearRec2020, DisplayView{}).Apply(c);
  for (double white : {1e-3, 1.0, 1e2, 1e4, 1e6, 1e7, 1e9}) {
    ColorProcessor p = Config().Display(ocio_names::kLinearRec2020, DisplayView{.white_cd_m2 = white});
    std::array<float, 3> in{static_cast<float>(c[0] * white), static_cast<float>(c[1] * white),
                            static_cast<float>(c[2] * white)};
    std::array<float, 3> out = p.Apply(in);
    std::vector<float> buffer(in.begin(), in.end());
    p.Apply(buffer);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(out[k], ref[k], 2e-6) << "white " << white << " channel " << k;
      EXPECT_EQ(buffer[k], out[k]) << "buffer and pixel paths agree";
    }
  }
}
