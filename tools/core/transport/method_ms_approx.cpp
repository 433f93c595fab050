#include "transport/method_ms_approx.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "io/error.h"
#include "transport/path_tracer.h"

namespace skybake {

namespace {
constexpr double kPi = std::numbers::pi;
}

const QualityTable<MsApproxSettings>& MsApproxPresets() {
  // The LUT's nodes, directions and ray ladder; the view rays march as `single` at the same quality.
  static const QualityTable<MsApproxSettings> presets = {{
      // low
      MsApproxSettings{.march = SingleMarchSettings(Quality::kLow), .lut_mu_s = 16, .lut_z = 16, .sqrt_dirs = 4,
                       .ray_dz_min_m = 1000, .ray_dz_rel = 0.5, .ray_max_piece_m = 200e3},
      // medium: Hillaire 2020 Table 2, a 32 x 32 LUT, 64 directions, 20 samples per ray.
      MsApproxSettings{.march = SingleMarchSettings(Quality::kMedium), .lut_mu_s = 32, .lut_z = 32, .sqrt_dirs = 8,
                       .ray_dz_min_m = 300, .ray_dz_rel = 0.25, .ray_max_piece_m = 50e3},
      // high
      MsApproxSettings{.march = SingleMarchSettings(Quality::kHigh), .lut_mu_s = 64, .lut_z = 64, .sqrt_dirs = 16,
                       .ray_dz_min_m = 100, .ray_dz_rel = 0.1, .ray_max_piece_m = 20e3},
  }};
  return presets;
}

MsApproxSettings MsApproxPreset(Quality quality) { return MsApproxPresets()[quality]; }

MultipleScatteringLut::MultipleScatteringLut(const SingleScatteringModel& ss, const MsApproxSettings& s,
                                             const ProgressFn& progress)
    : ss_(ss), s_(s), nw_(ss.model().wavelengths()), top_(ss.model().altitude_m.back()) {
  SKYBAKE_CHECK_GE(s.lut_mu_s, 2);
  SKYBAKE_CHECK_GE(s.lut_z, 2);
  SKYBAKE_CHECK_GE(s.sqrt_dirs, 1);
  const AtmosphereModel& m = ss.model();
  const size_t n_nodes = static_cast<size_t>(s.lut_mu_s) * s.lut_z;
  psi_.assign(n_nodes * nw_, 0.0);
  l2_.assign(n_nodes * nw_, 0.0);
  fms_.assign(n_nodes * nw_, 0.0);
  // Directions: the stratified sphere of NewMultiScattCS. Those with y < 0 mirror those with
  // y > 0 (azimuth 2 pi (i + 1/2)/n pairs with 2 pi (n - i - 1/2)/n), so only i < n/2 are traced,
  // with weight 2; for odd n the middle azimuth (i = (n - 1)/2, at 180 deg, in the plane y = 0)
  // is its own mirror and keeps weight 1.
  const int n = s.sqrt_dirs;
  struct Dir {
    glm::dvec3 v;
    double weight;  // fraction of the sphere
  };
  std::vector<Dir> dirs;
  for (int i = 0; i < (n + 1) / 2; ++i) {
    const double az = 2.0 * kPi * (i + 0.5) / n;
    const double mirror = (n % 2 == 1 && 2 * i + 1 == n) ? 1.0 : 2.0;
    for (int j = 0; j < n; ++j) {
      const double cz = 1.0 - 2.0 * (j + 0.5) / n;
      const double sz = std::sqrt(std::max(0.0, 1.0 - cz * cz));
      dirs.push_back({glm::dvec3(std::cos(az) * sz, std::sin(az) * sz, cz), mirror / (n * n)});
    }
  }
  SingleScatteringModel::RayOptions ro;
  ro.sun_phase = false;  // the isotropic phase of eq. 6
  ro.unit_sun = true;    // a transfer function per unit irradiance
  ro.point_sun = true;
  ro.ground = true;
  ro.dz_min_m = s.ray_dz_min_m;
  ro.dz_rel = s.ray_dz_rel;
  ro.max_piece_m = s.ray_max_piece_m;
  std::atomic<size_t> done{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n_nodes, 1), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<double> L(nw_), F(nw_);
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const int iz = static_cast<int>(k / s.lut_mu_s), im = static_cast<int>(k % s.lut_mu_s);
      const double z = top_ * iz / (s.lut_z - 1);
      const double mu_s = -1.0 + 2.0 * im / (s.lut_mu_s - 1);
      // Keep the point strictly inside the atmosphere (the top node would see no medium above).
      const glm::dvec3 x(0.0, 0.0, m.bottom_radius_m + std::min(z, top_ * (1.0 - 1e-9)));
      const glm::dvec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
      double* l2 = &l2_[k * nw_];
      double* fm = &fms_[k * nw_];
      for (const Dir& d : dirs) {
        ss_.MarchRay(x, d.v, sun, ro, L.data(), F.data());
        for (size_t w = 0; w < nw_; ++w) {
          l2[w] += d.weight * L[w];
          fm[w] += d.weight * F[w];
        }
      }
      double* psi = &psi_[k * nw_];
      for (size_t w = 0; w < nw_; ++w) {
        const double f = fm[w];
        double series;
        if (s.orders == 0) {
          series = 1.0 / (1.0 - f);
        } else {
          series = 0.0;
          double p = 1.0;
          for (int o = 2; o <= s.orders; ++o) {
            series += p;
            p *= f;
          }
        }
        psi[w] = l2[w] * series;
      }
      const size_t nd = ++done;
      if (progress && (nd % 64 == 0 || nd == n_nodes)) progress("multiple-scattering LUT", static_cast<double>(nd) / n_nodes);
    }
  });
}

void MultipleScatteringLut::Psi(double z, double mu_s, double* psi) const {
  std::fill(psi, psi + nw_, 0.0);
  std::vector<double> one(nw_, 1.0);
  Accumulate(z, mu_s, one.data(), psi);
}

// dst[wl] += scale[wl] * Psi(z, mu_s)[wl] (bilinear in the node values).
void MultipleScatteringLut::Accumulate(double z, double mu_s, const double* scale, double* dst) const {
  const double fz = std::clamp(z / top_, 0.0, 1.0) * (s_.lut_z - 1);
  const double fm = std::clamp(0.5 * (mu_s + 1.0), 0.0, 1.0) * (s_.lut_mu_s - 1);
  const int iz = std::min(static_cast<int>(fz), s_.lut_z - 2), im = std::min(static_cast<int>(fm), s_.lut_mu_s - 2);
  const double tz = fz - iz, tm = fm - im;
  const double w00 = (1 - tz) * (1 - tm), w01 = (1 - tz) * tm, w10 = tz * (1 - tm), w11 = tz * tm;
  const double* a = &psi_[(static_cast<size_t>(iz) * s_.lut_mu_s + im) * nw_];
  const double* b = a + nw_;
  const double* c = a + static_cast<size_t>(s_.lut_mu_s) * nw_;
  const double* d = c + nw_;
  for (size_t w = 0; w < nw_; ++w) dst[w] += scale[w] * (w00 * a[w] + w01 * b[w] + w10 * c[w] + w11 * d[w]);
}

void MultipleScatteringLut::Add(double z, double mu_sun, const double* sigma_s, double* src) const {
  // source += sigma_s Psi_ms E_0 (Hillaire 2020 eq. 11), E_0 folded into the scale.
  const std::vector<double>& e0 = ss_.model().sun.irradiance;
  thread_local std::vector<double> scale;
  scale.resize(nw_);
  for (size_t w = 0; w < nw_; ++w) scale[w] = sigma_s[w] * e0[w];
  Accumulate(z, mu_sun, scale.data(), src);
}

namespace {

class MsApproxMethod : public SkyMethod {
 public:
  MsApproxMethod(const AtmosphereModel& model, const MsApproxSettings& s, std::string quality, const ProgressFn& progress)
      : quality_(std::move(quality)), s_(s), ss_(model, s.march), lut_(ss_, s, progress) {}
  std::string Name() const override { return "ms-approx"; }
  std::string Describe() const override {
    return fmt::format(
        "method: ms-approx\nquality: {}\n{}ms_lut: {{mu_s: {}, altitude: {}, directions: {}, ray_dz_min_m: {}, "
        "ray_dz_rel: {}, ray_max_piece_m: {}}}\norders: {}\n",
        quality_, DescribeMarchSettings(s_.march), s_.lut_mu_s, s_.lut_z, s_.sqrt_dirs * s_.sqrt_dirs, s_.ray_dz_min_m,
        s_.ray_dz_rel, s_.ray_max_piece_m, s_.orders == 0 ? std::string("all") : std::to_string(s_.orders));
  }
  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    const AtmosphereModel& m = ss_.model();
    const size_t nw = m.wavelengths();
    const glm::dvec3 x(0, 0, m.bottom_radius_m + observer_altitude_m);
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
    out->assign(dirs.size() * nw, 0.0);
    SingleScatteringModel::RayOptions o;
    if (s_.orders != 1) o.extra = &lut_;
    for (size_t d = 0; d < dirs.size(); ++d) {
      const glm::dvec3 v = glm::normalize(glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]));
      ss_.MarchRay(x, v, sun, o, out->data() + d * nw);
    }
  }
  // The same march without the multiple-scattering source (the `single` method's value).
  bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad,
                                const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const override {
    const AtmosphereModel& m = ss_.model();
    const size_t nw = m.wavelengths();
    const glm::dvec3 x(0, 0, m.bottom_radius_m + observer_altitude_m);
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
    out->assign(dirs.size() * nw, 0.0);
    SingleScatteringModel::RayOptions o;
    for (size_t d = 0; d < dirs.size(); ++d) {
      const glm::dvec3 v = glm::normalize(glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]));
      ss_.MarchRay(x, v, sun, o, out->data() + d * nw);
    }
    return true;
  }

 private:
  std::string quality_;
  MsApproxSettings s_;
  SingleScatteringModel ss_;
  MultipleScatteringLut lut_;
};

}  // namespace

std::unique_ptr<SkyMethod> MakeMsApproxMethod(const AtmosphereModel& model, const SkyMethodOptions& options,
                                              const ProgressFn& progress) {
  MsApproxSettings s = MsApproxPreset(options.quality);
  if (options.orders < 0) throw UsageError(fmt::format("--orders: expected >= 0, got {}", options.orders));
  s.orders = options.orders;
  return std::make_unique<MsApproxMethod>(model, s, QualityName(options.quality), progress);
}

std::unique_ptr<SkyMethod> MakeMsApproxMethod(const AtmosphereModel& model, const MsApproxSettings& settings,
                                              const ProgressFn& progress) {
  return std::make_unique<MsApproxMethod>(model, settings, "custom", progress);
}

}  // namespace skybake
