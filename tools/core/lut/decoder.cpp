#include "lut/decoder.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>

#include <fmt/format.h>

#include "io/error.h"
#include "lut/r11g11b10.h"

namespace skybake::lut {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::vector<double> Numbers(const ktx2::Texture& t, const std::string& key, size_t count, const std::string& name) {
  const std::string v = t.GetString(key);
  std::vector<double> out;
  const char* p = v.data();
  const char* e = v.data() + v.size();
  while (p < e) {
    while (p < e && *p == ' ') ++p;
    if (p == e) break;
    double x = 0.0;
    auto r = std::from_chars(p, e, x);
    if (r.ec != std::errc()) break;
    out.push_back(x);
    p = r.ptr;
  }
  if (out.size() != count || v.empty()) {
    throw InputError(FileLoc{name, 0}, fmt::format("KTX2 key '{}' must hold {} number{}, got \"{}\"", key, count,
                                                   count == 1 ? "" : "s", v));
  }
  return out;
}

}  // namespace

const char* TimeInterpolationName(TimeInterpolation t) {
  return t == TimeInterpolation::kLinear ? "linear" : "geometric";
}

SkyLutDecoder::SkyLutDecoder(int width, int height, gt7::TimeMapping time, gt7::SphereMapping sphere, std::vector<float> rgb,
                             std::array<double, 3> night_rgb, double night_end_zenith_deg)
    : w_(width), h_(height), time_(time), sphere_(sphere), rgb_(std::move(rgb)), night_(night_rgb),
      night_end_rad_(night_end_zenith_deg * kDeg) {
  SKYBAKE_CHECK_EQ(rgb_.size(), static_cast<size_t>(w_) * h_ * time_.slices() * 3);
}

SkyLutDecoder SkyLutDecoder::FromKtx2(const ktx2::Texture& t, const std::string& name) {
  if (t.format.vk_format != ktx2::VkFormat::kB10G11R11UfloatPack32) {
    throw InputError(FileLoc{name, 0}, "not a B10G11R11_UFLOAT_PACK32 texture");
  }
  const uint32_t slices = t.depth > 0 ? t.depth : t.layers;
  const std::string tm_name = t.GetString("skybake.time_mapping.name");
  const std::optional<gt7::TimeMappingKind> n = gt7::TimeMapping::ParseName(tm_name);
  if (!n) throw InputError(FileLoc{name, 0}, "KTX2 key 'skybake.time_mapping.name' is not a GT7 time mapping: \"" + tm_name + "\"");
  SkyLutDecoder d;
  d.name_ = t.GetString("skybake.basis_sky");
  d.w_ = static_cast<int>(t.width);
  d.h_ = static_cast<int>(t.height);
  d.time_.upper_slices = n->upper;
  d.time_.lower_slices = n->lower;
  d.time_.upper_power = n->upper_power;
  d.time_.observer_radius_m = Numbers(t, "skybake.time_mapping.observer_radius_m", 1, name)[0];
  d.time_.top_radius_m = Numbers(t, "skybake.time_mapping.top_radius_m", 1, name)[0];
  if (static_cast<int>(slices) != d.time_.slices() || t.height == 0) {
    throw InputError(FileLoc{name, 0}, fmt::format("{} slices, but the time mapping '{}' has {}", slices, tm_name, d.time_.slices()));
  }
  d.sphere_.threshold_elevation_deg = Numbers(t, "skybake.sphere_mapping.threshold_elevation_deg", 1, name)[0];
  const double scale = Numbers(t, "skybake.scale", 1, name)[0];
  if (!(scale > 0.0)) throw InputError(FileLoc{name, 0}, "skybake.scale must be positive");
  const std::vector<double> night = Numbers(t, "skybake.night_rgb", 3, name);
  d.night_ = {night[0], night[1], night[2]};
  d.night_end_rad_ = Numbers(t, "skybake.night_end_zenith_deg", 1, name)[0] * kDeg;
  const std::string grid = t.GetString("skybake.texel_grid");
  if (!grid.empty()) {
    const std::optional<gt7::TexelGrid> g = gt7::ParseTexelGrid(grid);
    if (!g) throw InputError(FileLoc{name, 0}, "KTX2 key 'skybake.texel_grid' must be \"centres\" or \"nodes\", got \"" + grid + "\"");
    if (*g == gt7::TexelGrid::kNodes && (d.w_ < 2 || d.h_ < 2)) {
      throw InputError(FileLoc{name, 0}, "the node texel grid needs at least 2 x 2 texels per slice");
    }
    d.grid_ = *g;
  }
  d.rgb_ = r11g11b10::UnpackTexels(t.data);
  for (float& v : d.rgb_) v = static_cast<float>(v / scale);
  return d;
}

void SkyLutDecoder::set_texel_grid(gt7::TexelGrid g) {
  SKYBAKE_CHECK(g == gt7::TexelGrid::kCentres || (w_ >= 2 && h_ >= 2));
  grid_ = g;
}

std::array<double, 3> SkyLutDecoder::Sample(int k, double u, double v) const {
  const bool nodes = grid_ == gt7::TexelGrid::kNodes;
  const double x = nodes ? u * (w_ - 1) : u * w_ - 0.5, y = nodes ? v * (h_ - 1) : v * h_ - 0.5;
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, w_ - 1), y0 = std::clamp(static_cast<int>(std::floor(y)), 0, h_ - 1);
  const int x1 = std::min(x0 + 1, w_ - 1), y1 = std::min(y0 + 1, h_ - 1);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  const size_t base = static_cast<size_t>(k) * w_ * h_;
  auto at = [&](int xx, int yy, int c) { return static_cast<double>(rgb_[(base + static_cast<size_t>(yy) * w_ + xx) * 3 + c]); };
  std::array<double, 3> out;
  for (int c = 0; c < 3; ++c) {
    out[c] = (1 - fy) * ((1 - fx) * at(x0, y0, c) + fx * at(x1, y0, c)) + fy * ((1 - fx) * at(x0, y1, c) + fx * at(x1, y1, c));
  }
  return out;
}

std::array<double, 3> SkyLutDecoder::SliceRadiance(int k, const std::array<double, 3>& d, double theta) const {
  const gt7::SphereFamily f = sphere_.FamilyFor(time_.SliceZenithRad(k));
  const double theta_eval = f == gt7::SphereFamily::kSunAligned ? std::min(theta, sphere_.ThresholdZenithRad()) : theta;
  const std::array<double, 2> uv = gt7::SphereMapping::UvIn(f, d, theta_eval);
  return Sample(k, uv[0], uv[1]);
}

std::pair<int, double> SkyLutDecoder::SliceBlend(double theta) const {
  const int n = slices();
  if (theta > time_.SliceZenithRad(n - 1)) return {n - 1, 0.0};
  const int i = std::min(static_cast<int>(std::floor(time_.SliceCoordinate(theta))), n - 2);
  const double a_rad = time_.SliceZenithRad(i), b_rad = time_.SliceZenithRad(i + 1);
  const double t = b_rad > a_rad ? std::clamp((theta - a_rad) / (b_rad - a_rad), 0.0, 1.0) : 0.0;
  return {i, t};
}

std::array<double, 3> SkyLutDecoder::Radiance(const std::array<double, 3>& d, double theta) const {
  const int n = slices();
  const double theta_last = time_.SliceZenithRad(n - 1);
  if (theta > theta_last) {
    const double f = night_end_rad_ > theta_last ? std::clamp((theta - theta_last) / (night_end_rad_ - theta_last), 0.0, 1.0) : 1.0;
    const std::array<double, 3> last = SliceRadiance(n - 1, d, theta_last);
    return {(1 - f) * last[0] + f * night_[0], (1 - f) * last[1] + f * night_[1], (1 - f) * last[2] + f * night_[2]};
  }
  const auto [i, t] = SliceBlend(theta);
  const std::array<double, 3> a = SliceRadiance(i, d, theta);
  if (t <= 0.0) return a;
  const std::array<double, 3> b = SliceRadiance(i + 1, d, theta);
  if (interp_ == TimeInterpolation::kLinear) {
    return {(1 - t) * a[0] + t * b[0], (1 - t) * a[1] + t * b[1], (1 - t) * a[2] + t * b[2]};
  }
  std::array<double, 3> out;
  for (int c = 0; c < 3; ++c) {
    out[c] = std::exp((1 - t) * std::log(std::max(a[c], kGeometricFloorCdM2)) + t * std::log(std::max(b[c], kGeometricFloorCdM2)));
  }
  return out;
}

std::array<double, 3> BlendRadiance(const std::vector<std::pair<const SkyLutDecoder*, double>>& weighted,
                                    const std::array<double, 3>& d, double theta) {
  std::array<double, 3> out{0, 0, 0};
  for (const auto& [lut, w] : weighted) {
    const std::array<double, 3> l = lut->Radiance(d, theta);
    for (int c = 0; c < 3; ++c) out[c] += w * l[c];
  }
  return out;
}

}  // namespace skybake::lut
