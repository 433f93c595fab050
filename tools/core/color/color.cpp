#include "color/color.h"

#include <OpenColorIO/OpenColorIO.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <mutex>

#include <fmt/format.h>

#include "io/error.h"
#include "io/png.h"
#include "io/repo_paths.h"

namespace OCIO = OCIO_NAMESPACE;
namespace fs = std::filesystem;

namespace skybake {

const char* XyzColorSpace(Observer observer) {
  switch (observer) {
    case Observer::kCie1931_2deg: return ocio_names::kCieXyzD65;
    case Observer::kCie2006_2deg: return ocio_names::kCie2006Xyz;
  }
  return "";
}

double DisplayView::Scale() const { return std::exp2(exposure_stops) / white_cd_m2; }

// ------------------------------------------------------------------------------- processors

struct ColorProcessor::Impl {
  OCIO::ConstCPUProcessorRcPtr cpu;
  // A uniform scale applied before the OCIO processor (the preview exposure k), 1 otherwise.
  // Not an OCIO MatrixTransform: observed with OCIO 2.1.2, composing matrices
  // (OPTIMIZATION_COMP_MATRIX, part of LOSSLESS) drops entries of the product below ~1e-7, so
  // diag(1e-7) followed by Linear Rec.2020 -> XYZ turned (5e6, 5e6, 5e6) into (0, 0, 0.53)
  // instead of (0.475, 0.5, 0.545), and 1e-6 shifted the hue. Absolute skies need k ~ 1e-4 to
  // 1e-9, so the scale is applied here, in double (tests/color Preview.ExposureIsExactOverManyStops).
  double scale = 1.0;
  std::string description;
  std::string cache_id;
};

namespace {
// Pixels per chunk of a parallel Apply: fixed, so the split does not depend on the threads.
constexpr size_t kChunkPixels = 4096;
const std::string kEmpty;
}  // namespace

void ColorProcessor::Apply(std::span<float> rgb) const {
  if (!impl_) throw InternalError("ColorProcessor::Apply on an empty processor");
  SKYBAKE_CHECK_EQ(rgb.size() % 3, size_t{0});
  const size_t pixels = rgb.size() / 3;
  if (pixels == 0) return;
  const OCIO::ConstCPUProcessorRcPtr& cpu = impl_->cpu;
  const double scale = impl_->scale;
  auto run = [&](size_t begin, size_t end) {
    if (scale != 1.0) {
      for (size_t i = begin * 3; i < end * 3; ++i) rgb[i] = static_cast<float>(static_cast<double>(rgb[i]) * scale);
    }
    OCIO::PackedImageDesc desc(rgb.data() + begin * 3, static_cast<long>(end - begin), 1, 3);
    cpu->apply(desc);
  };
  if (pixels <= kChunkPixels) {
    run(0, pixels);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, kChunkPixels),
                    [&](const tbb::blocked_range<size_t>& r) { run(r.begin(), r.end()); }, tbb::simple_partitioner());
}

std::array<float, 3> ColorProcessor::Apply(std::array<float, 3> rgb) const {
  if (!impl_) throw InternalError("ColorProcessor::Apply on an empty processor");
  if (impl_->scale != 1.0) {
    for (float& v : rgb) v = static_cast<float>(static_cast<double>(v) * impl_->scale);
  }
  impl_->cpu->applyRGB(rgb.data());
  return rgb;
}

const std::string& ColorProcessor::description() const { return impl_ ? impl_->description : kEmpty; }
const std::string& ColorProcessor::cache_id() const { return impl_ ? impl_->cache_id : kEmpty; }

// ------------------------------------------------------------------------------- config

struct ColorConfig::Impl {
  fs::path path;
  OCIO::ConstConfigRcPtr config;
  // OCIO issue #1216: one thread at a time inside the Config (recursive: error paths list names).
  std::recursive_mutex mutex;
};

fs::path ColorConfig::ResolvePath(const fs::path& explicit_path) {
  auto check = [](const fs::path& p, const std::string& how) {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) {
      throw InputError(FileLoc{p.string(), 0}, fmt::format("cannot read the OCIO config ({})", how));
    }
    return p;
  };
  if (!explicit_path.empty()) return check(explicit_path, "given with --ocio-config");
  if (const char* env = std::getenv("SKYBAKE_OCIO"); env != nullptr && env[0] != '\0') {
    return check(fs::path(env), "named by $SKYBAKE_OCIO");
  }
  return FindRepoFile("ocio/config.ocio");
}

ColorConfig ColorConfig::Load(const fs::path& explicit_path) {
  ColorConfig c;
  auto impl = std::make_shared<Impl>();
  impl->path = ResolvePath(explicit_path);
  try {
    impl->config = OCIO::Config::CreateFromFile(impl->path.string().c_str());
    impl->config->validate();
  } catch (const OCIO::Exception& e) {
    throw InputError(FileLoc{impl->path.string(), 0}, std::string("invalid OCIO config: ") + e.what());
  }
  c.impl_ = std::move(impl);
  return c;
}

const fs::path& ColorConfig::path() const { return impl_->path; }
std::string ColorConfig::cache_id() const {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  return impl_->config->getCacheID();
}

std::vector<std::string> ColorConfig::ColorSpaces() const {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  std::vector<std::string> out;
  for (int i = 0; i < impl_->config->getNumColorSpaces(); ++i) out.emplace_back(impl_->config->getColorSpaceNameByIndex(i));
  return out;
}

std::vector<std::string> ColorConfig::Displays() const {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  std::vector<std::string> out;
  for (int i = 0; i < impl_->config->getNumDisplays(); ++i) out.emplace_back(impl_->config->getDisplay(i));
  return out;
}

std::vector<std::string> ColorConfig::Views(const std::string& display) const {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  std::vector<std::string> out;
  for (int i = 0; i < impl_->config->getNumViews(display.c_str()); ++i) {
    out.emplace_back(impl_->config->getView(display.c_str(), i));
  }
  return out;
}

namespace {
std::string Quoted(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
  return s;
}
}  // namespace

ColorProcessor ColorConfig::Converter(std::string_view src, std::string_view dst) const {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  const std::string s(src), d(dst);
  for (const std::string& name : {s, d}) {
    if (!impl_->config->getColorSpace(name.c_str())) {
      throw InputError(FileLoc{impl_->path.string(), 0},
                       fmt::format("no colour space '{}' in the OCIO config (it has {})", name, Quoted(ColorSpaces())));
    }
  }
  auto impl = std::make_shared<ColorProcessor::Impl>();
  try {
    OCIO::ConstProcessorRcPtr p = impl_->config->getProcessor(s.c_str(), d.c_str());
    impl->cpu = p->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32, OCIO::OPTIMIZATION_LOSSLESS);
    impl->cache_id = p->getCacheID();
  } catch (const OCIO::Exception& e) {
    throw InputError(FileLoc{impl_->path.string(), 0}, fmt::format("OCIO: {} -> {}: {}", s, d, e.what()));
  }
  impl->description = s + " -> " + d;
  ColorProcessor out;
  out.impl_ = std::move(impl);
  return out;
}

ColorProcessor ColorConfig::Display(std::string_view src, const DisplayView& view) const {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  const std::string s(src);
  const FileLoc where{impl_->path.string(), 0};
  OCIO::ConstColorSpaceRcPtr cs = impl_->config->getColorSpace(s.c_str());
  if (!cs) {
    throw InputError(where, fmt::format("no colour space '{}' in the OCIO config (it has {})", s, Quoted(ColorSpaces())));
  }
  if (cs->getReferenceSpaceType() != OCIO::REFERENCE_SPACE_SCENE || cs->isData()) {
    throw InputError(where, fmt::format("a preview needs a scene-referred colour space, not '{}'", s));
  }
  const std::vector<std::string> displays = Displays();
  if (std::find(displays.begin(), displays.end(), view.display) == displays.end()) {
    throw InputError(where, fmt::format("no display '{}' in the OCIO config (it has {})", view.display, Quoted(displays)));
  }
  const std::vector<std::string> views = Views(view.display);
  if (std::find(views.begin(), views.end(), view.view) == views.end()) {
    throw InputError(where, fmt::format("display '{}' has no view '{}' (it has {})", view.display, view.view, Quoted(views)));
  }
  const double k = view.Scale();
  if (!std::isfinite(k) || !(k > 0.0)) {
    throw InputError(where, fmt::format("preview exposure: 2^{} / {} cd/m2 is not a positive scale", view.exposure_stops,
                                        view.white_cd_m2));
  }
  auto impl = std::make_shared<ColorProcessor::Impl>();
  // The exposure is a uniform scale of linear values, so it commutes with the linear source
  // space; it is applied by Apply before the OCIO display view (see Impl::scale).
  impl->scale = k;
  try {
    OCIO::DisplayViewTransformRcPtr dv = OCIO::DisplayViewTransform::Create();
    dv->setSrc(s.c_str());
    dv->setDisplay(view.display.c_str());
    dv->setView(view.view.c_str());
    OCIO::ConstProcessorRcPtr p = impl_->config->getProcessor(dv);
    impl->cpu = p->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32, OCIO::OPTIMIZATION_LOSSLESS);
    impl->cache_id = fmt::format("{} scale {}", p->getCacheID(), k);
  } catch (const OCIO::Exception& e) {
    throw InputError(where, fmt::format("OCIO: {} -> {}/{}: {}", s, view.display, view.view, e.what()));
  }
  impl->description = fmt::format("{} -> {}/{} (scale {})", s, view.display, view.view, k);
  ColorProcessor out;
  out.impl_ = std::move(impl);
  return out;
}

std::string ColorConfig::DisplayShaderGlslEs3(std::string_view src, const DisplayView& view, const std::string& function_name) const {
  (void)Display(src, view);  // the same checks of the names and the exposure
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  const std::string s(src);
  const FileLoc where{impl_->path.string(), 0};
  try {
    OCIO::DisplayViewTransformRcPtr dv = OCIO::DisplayViewTransform::Create();
    dv->setSrc(s.c_str());
    dv->setDisplay(view.display.c_str());
    dv->setView(view.view.c_str());
    OCIO::ConstProcessorRcPtr p = impl_->config->getProcessor(dv);
    OCIO::GpuShaderDescRcPtr desc = OCIO::GpuShaderDesc::CreateShaderDesc();
    desc->setLanguage(OCIO::GPU_LANGUAGE_GLSL_ES_3_0);
    desc->setFunctionName(function_name.c_str());
    desc->setResourcePrefix("ocio_");
    p->getDefaultGPUProcessor()->extractGpuShaderInfo(desc);
    if (desc->getNumUniforms() != 0 || desc->getNumTextures() != 0 || desc->getNum3DTextures() != 0) {
      throw InputError(where, fmt::format("OCIO: the GPU shader of {} -> {}/{} needs {} uniforms, {} 1D/2D and {} 3D textures; "
                                          "only views without resources are exported",
                                          s, view.display, view.view, desc->getNumUniforms(), desc->getNumTextures(),
                                          desc->getNum3DTextures()));
    }
    return desc->getShaderText();
  } catch (const OCIO::Exception& e) {
    throw InputError(where, fmt::format("OCIO: GPU shader of {} -> {}/{}: {}", s, view.display, view.view, e.what()));
  }
}

// ------------------------------------------------------------------------------- previews

std::vector<uint8_t> QuantizeDisplay8(std::span<const float> v) {
  std::vector<uint8_t> out(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const float f = v[i];
    const double c = std::isnan(f) ? 0.0 : std::clamp(static_cast<double>(f), 0.0, 1.0);
    out[i] = static_cast<uint8_t>(std::lround(c * 255.0));
  }
  return out;
}

std::vector<uint8_t> EncodePreview8(int width, int height, std::span<const float> rgb, const ColorProcessor& display) {
  SKYBAKE_CHECK(width > 0 && height > 0);
  SKYBAKE_CHECK_EQ(rgb.size(), static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  std::vector<float> work(rgb.begin(), rgb.end());
  display.Apply(work);
  return QuantizeDisplay8(work);
}

bool WritePreviewPng(const fs::path& path, int width, int height, std::span<const float> rgb,
                     const ColorProcessor& display) {
  return WritePng8(path, width, height, 3, EncodePreview8(width, height, rgb, display));
}

}  // namespace skybake
