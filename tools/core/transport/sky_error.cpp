#include "transport/sky_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "io/error.h"

namespace skybake {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
}  // namespace

SkyDirections ChartDirections() {
  const std::vector<double> rows = {10, 20, 30, 40, 50, 60, 70, 80, 85, 88};
  constexpr int kAz = 9;  // 0, 22.5, ..., 180 deg
  SkyDirections s;
  auto add = [&](double theta, double phi, double omega) {
    s.theta_deg.push_back(theta);
    s.phi_deg.push_back(phi);
    s.solid_angle_sr.push_back(omega);
    const double t = theta * kDeg, p = phi * kDeg;
    s.dirs.push_back({std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)});
  };
  // The zenith cap up to the middle of the first row.
  add(0.0, 0.0, 2 * kPi * (1 - std::cos(0.5 * rows[0] * kDeg)));
  for (size_t r = 0; r < rows.size(); ++r) {
    const double lo = 0.5 * ((r == 0 ? 0.0 : rows[r - 1]) + rows[r]);
    const double hi = r + 1 < rows.size() ? 0.5 * (rows[r] + rows[r + 1]) : 90.0;
    const double band = std::cos(lo * kDeg) - std::cos(hi * kDeg);
    for (int a = 0; a < kAz; ++a) {
      const double dphi = (a == 0 || a == kAz - 1 ? 0.5 : 1.0) * kPi / (kAz - 1);
      add(rows[r], 180.0 * a / (kAz - 1), 2.0 * dphi * band);  // x 2: the mirrored half
    }
  }
  return s;
}

std::vector<std::array<double, 3>> SpectralToXyz(const std::vector<double>& L, const std::vector<std::array<double, 3>>& w) {
  const size_t nw = w.size();
  SKYBAKE_CHECK_EQ(L.size() % nw, size_t{0});
  std::vector<std::array<double, 3>> out(L.size() / nw, {0, 0, 0});
  for (size_t d = 0; d < out.size(); ++d) {
    for (size_t i = 0; i < nw; ++i) {
      for (size_t c = 0; c < 3; ++c) out[d][c] += w[i][c] * L[d * nw + i];
    }
  }
  return out;
}

SkyError CompareSkies(const SkyCompareInput& in, std::vector<double>* per_direction) {
  const SkyDirections& D = *in.directions;
  const size_t n = D.dirs.size();
  SKYBAKE_CHECK_EQ(in.ref_xyz->size(), n);
  SKYBAKE_CHECK_EQ(in.test_xyz->size(), n);
  const std::array<double, 3> sun = {std::sin(in.sun_zenith_rad), 0.0, std::cos(in.sun_zenith_rad)};
  std::vector<float> ref_rgb, test_rgb, ref_ciexyz, test_ciexyz;
  for (size_t d = 0; d < n; ++d) {
    for (size_t c = 0; c < 3; ++c) {
      ref_rgb.push_back(static_cast<float>((*in.ref_xyz)[d][c]));
      test_rgb.push_back(static_cast<float>((*in.test_xyz)[d][c]));
    }
  }
  ref_ciexyz = ref_rgb;
  test_ciexyz = test_rgb;
  in.to_rec2020->Apply(ref_rgb);
  in.to_rec2020->Apply(test_rgb);
  in.to_reference->Apply(ref_ciexyz);
  in.to_reference->Apply(test_ciexyz);
  auto uv = [](const float* xyz) {
    const double den = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    return std::array<double, 2>{4.0 * xyz[0] / den, 9.0 * xyz[1] / den};
  };
  SkyError e;
  double sw = 0.0, se2 = 0.0, sn2 = 0.0, sc2 = 0.0, suv2 = 0.0;
  if (per_direction) per_direction->assign(n, std::numeric_limits<double>::quiet_NaN());
  for (size_t d = 0; d < n; ++d) {
    const double cos_sun = D.dirs[d][0] * sun[0] + D.dirs[d][1] * sun[1] + D.dirs[d][2] * sun[2];
    if (std::acos(std::clamp(cos_sun, -1.0, 1.0)) <= in.aureole_deg * kDeg) continue;
    const double yr = (*in.ref_xyz)[d][1], yt = (*in.test_xyz)[d][1];
    if (!(yr > 0.0)) continue;  // a black reference direction cannot carry a relative error
    const double w = D.solid_angle_sr[d];
    const double rel = yt / yr - 1.0;
    const double noise = in.ref_y_stderr ? (*in.ref_y_stderr)[d] / yr : 0.0;
    double c2 = 0.0;
    const double scale = yt > 0.0 ? yr / yt : 0.0;
    for (size_t c = 0; c < 3; ++c) {
      const double diff = test_rgb[d * 3 + c] * scale - ref_rgb[d * 3 + c];
      c2 += diff * diff;
    }
    c2 /= 3.0 * yr * yr;
    double duv2 = 0.0;
    if (yt > 0.0) {
      const std::array<double, 2> a = uv(&ref_ciexyz[d * 3]), b = uv(&test_ciexyz[d * 3]);
      duv2 = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]);
    }
    sw += w;
    se2 += w * rel * rel;
    sn2 += w * noise * noise;
    sc2 += w * c2;
    suv2 += w * duv2;
    e.max = std::max(e.max, std::abs(rel));
    e.ref_noise_max = std::max(e.ref_noise_max, noise);
    ++e.directions;
    if (per_direction) (*per_direction)[d] = rel;
  }
  if (sw > 0.0) {
    e.rms = std::sqrt(se2 / sw);
    e.ref_noise_rms = std::sqrt(sn2 / sw);
    e.rms_corrected = std::sqrt(std::max(0.0, (se2 - sn2) / sw));
    e.color_rms = std::sqrt(sc2 / sw);
    e.duv_rms = std::sqrt(suv2 / sw);
  }
  return e;
}

}  // namespace skybake
