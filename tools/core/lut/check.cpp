#include "lut/check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <fmt/format.h>

#include "io/error.h"
#include "io/exr.h"
#include "lut/directions.h"

namespace skybake::lut {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// "key: value" line of a provenance parameter block.
std::string ParamLine(const std::string& params, const std::string& key) {
  size_t at = 0;
  while ((at = params.find(key + ": ", at)) != std::string::npos) {
    if (at == 0 || params[at - 1] == '\n') {
      const size_t b = at + key.size() + 2, e = params.find('\n', b);
      return params.substr(b, e == std::string::npos ? std::string::npos : e - b);
    }
    at += key.size();
  }
  return "";
}

struct Accum {
  double w = 0.0, e2 = 0.0, e = 0.0;
  void Add(double weight, double err) {
    w += weight;
    e2 += weight * err * err;
    e += weight * err;
  }
  double Rms() const { return w > 0.0 ? std::sqrt(e2 / w) : 0.0; }
  double Mean() const { return w > 0.0 ? e / w : 0.0; }
};

}  // namespace

CheckResult CheckAgainstDirect(const std::vector<std::pair<const SkyLutDecoder*, double>>& luts, const std::filesystem::path& direct,
                               const ColorConfig& config, double sun_cone_deg) {
  SKYBAKE_CHECK(!luts.empty());
  const std::string name = direct.string();
  auto fail = [&](const std::string& msg) { throw InputError(FileLoc{name, 0}, msg); };
  const std::vector<ExrPart> parts = ReadExrParts(direct);
  CheckResult res;
  res.direct = name;
  res.sun_cone_deg = sun_cone_deg;
  const ColorProcessor to_xyz = config.Converter(ocio_names::kLinearRec2020, ocio_names::kCieXyzD65);
  Accum all, all_cone;
  for (const ExrPart& part : parts) {
    if (part.name.rfind("sky.", 0) != 0) continue;
    const ExrImage& img = part.image;
    auto params = img.strings.find("skybake.parameters");
    auto sza = img.doubles.find("skybake.sun_zenith_deg");
    if (params == img.strings.end() || sza == img.doubles.end()) fail("part '" + part.name + "' is not a sky-render slice");
    const std::optional<DirectionMapping> m = ParseDirectionMapping(ParamLine(params->second, "mapping"));
    if (!m) {
      fail("part '" + part.name + "': the direct render must be equirectangular or fisheye, not '" +
           ParamLine(params->second, "mapping") + "'");
    }
    const DirectionGrid g{*m, img.width, img.height};
    res.direct_mapping = g.Describe();
    const int yc = img.ChannelIndex("G");
    if (yc < 0) fail("part '" + part.name + "' has no G (= Y) channel");
    const double ts = sza->second * kDeg;
    const std::array<double, 3> sun = {std::sin(ts), 0.0, std::cos(ts)};
    CheckSlice cs;
    cs.sun_zenith_deg = sza->second;
    cs.slice_coordinate = luts[0].first->time().SliceCoordinate(ts);
    // Decode every texel, then one OCIO conversion for the luminances.
    const size_t texels = static_cast<size_t>(img.width) * img.height;
    std::vector<float> rgb(texels * 3, 0.0f);
    std::vector<std::optional<std::array<double, 3>>> dirs(texels);
    for (size_t t = 0; t < texels; ++t) {
      dirs[t] = g.TexelDirection(static_cast<int>(t % img.width), static_cast<int>(t / img.width));
      if (!dirs[t]) continue;
      const std::array<double, 3> l = BlendRadiance(luts, *dirs[t], ts);
      for (int c = 0; c < 3; ++c) rgb[t * 3 + c] = static_cast<float>(l[c]);
    }
    to_xyz.Apply(rgb);
    Accum up, lo, up_cone, lo_cone;
    for (size_t t = 0; t < texels; ++t) {
      if (!dirs[t]) continue;
      const std::array<double, 3>& d = *dirs[t];
      const double y_direct = img.pixels[t * img.channels.size() + yc];
      if (!(y_direct > 0.0)) {
        ++cs.skipped;
        continue;
      }
      ++cs.texels;
      const double e = (rgb[t * 3 + 1] - y_direct) / y_direct;
      const double w = g.TexelSolidAngle(static_cast<int>(t % img.width), static_cast<int>(t / img.width));
      const double sun_angle = std::acos(std::clamp(d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2], -1.0, 1.0)) / kDeg;
      CheckWhere where{e, std::acos(std::clamp(d[2], -1.0, 1.0)) / kDeg, std::atan2(d[1], d[0]) / kDeg, sun_angle, y_direct,
                       rgb[t * 3 + 1]};
      const bool upper = d[2] > 0.0, outside = sun_angle > sun_cone_deg;
      (upper ? up : lo).Add(w, e);
      if (outside) (upper ? up_cone : lo_cone).Add(w, e);
      if (upper) {
        all.Add(w, e);
        if (outside) all_cone.Add(w, e);
        if (std::fabs(e) > std::fabs(cs.max_upper.error)) cs.max_upper = where;
        if (outside && std::fabs(e) > std::fabs(cs.max_upper_outside_cone.error)) cs.max_upper_outside_cone = where;
      } else if (std::fabs(e) > std::fabs(cs.max_lower.error)) {
        cs.max_lower = where;
      }
    }
    cs.rms_upper = up.Rms();
    cs.rms_lower = lo.Rms();
    cs.rms_upper_outside_cone = up_cone.Rms();
    cs.rms_lower_outside_cone = lo_cone.Rms();
    cs.mean_upper = up.Mean();
    res.worst_slice_rms_upper = std::max(res.worst_slice_rms_upper, cs.rms_upper);
    res.slices.push_back(cs);
  }
  if (res.slices.empty()) fail("no sky parts");
  res.rms_upper_all = all.Rms();
  res.rms_upper_all_outside_cone = all_cone.Rms();
  return res;
}

}  // namespace skybake::lut
