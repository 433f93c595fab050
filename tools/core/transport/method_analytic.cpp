#include "transport/method_analytic.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "atmosphere/ray_sphere.h"
#include "io/error.h"
#include "transport/method_single.h"
#include "transport/path_tracer.h"

namespace skybake {

AnalyticSky::AnalyticSky(const AtmosphereModel& m) : model_(m) {
  const size_t nl = m.levels(), nw = m.wavelengths();
  const double top = m.altitude_m.back();
  // Columns by the trapezoid rule: exact for coefficients linear between levels.
  auto column = [&](const std::vector<double>& coef, size_t w) {
    double c = 0.0;
    for (size_t i = 0; i + 1 < nl; ++i) c += 0.5 * (coef[i * nw + w] + coef[(i + 1) * nw + w]) * (m.altitude_m[i + 1] - m.altitude_m[i]);
    return c;
  };
  beta_e_.assign(nw, 0.0);
  for (const MediumComponent& c : m.components) {
    std::vector<double> bs(nw);
    for (size_t w = 0; w < nw; ++w) {
      bs[w] = column(c.scattering, w) / top;
      beta_e_[w] += bs[w] + column(c.absorption, w) / top;
    }
    if (c.phase) {
      beta_s_.push_back(bs);
      phase_.push_back(c.phase.get());
    }
  }
}

double AnalyticSky::DistanceToTop(const glm::dvec3& p, const glm::dvec3& w) const {
  return DistanceToSphereOutDot(glm::dot(p, w), glm::dot(p, p), model_.top_radius_m);
}

void AnalyticSky::Radiance(const glm::dvec3& x, const glm::dvec3& v, const glm::dvec3& sun, int steps, double* L) const {
  const size_t nw = model_.wavelengths();
  const RayExtent ext = ExtentOf(model_, x, v);
  const double dv = ext.length();
  const double nu = glm::dot(v, sun);
  const double mu_s = glm::dot(glm::normalize(x), sun);
  for (size_t w = 0; w < nw; ++w) {
    double f = 0.0;  // sum_c beta_s,c P_c(nu) / beta_e
    for (size_t c = 0; c < phase_.size(); ++c) f += beta_s_[c][w] * phase_[c]->Eval(w, nu);
    const double be = beta_e_[w];
    f = be > 0.0 ? f / be : 0.0;
    const double e0 = model_.sun.irradiance[w];
    if (steps <= 0) {
      const double k = 0.15 + 0.75 * mu_s;
      const double dl = std::max(DistanceToTop(x + v * (dv * k), sun), DistanceToTop(x + v * dv, sun));
      L[w] = e0 * std::exp(-be * dl) * f * (1.0 - std::exp(-be * dv));
    } else {
      const double D = dv / steps;
      const double step_scattering = f * (1.0 - std::exp(-be * D));
      const double step_t = std::exp(-be * D);
      double t = 1.0, sum = 0.0;
      for (int i = 0; i < steps; ++i) {
        sum += e0 * std::exp(-be * DistanceToTop(x + v * (D * i), sun)) * step_scattering * t;
        t *= step_t;
      }
      L[w] = sum;
    }
  }
}

const QualityTable<int>& AnalyticSteps() {
  // low: the improved formula (one point); medium: the blog's NUM_STEPS; high: a fine march.
  static const QualityTable<int> steps = {{0, 20, 200}};
  return steps;
}

namespace {

class AnalyticMethod : public SkyMethod {
 public:
  AnalyticMethod(const AtmosphereModel& model, const SkyMethodOptions& o)
      : quality_(o.quality), sky_(model), model_(model), steps_(AnalyticSteps()[o.quality]) {}
  std::string Name() const override { return "analytic"; }
  std::string Describe() const override {
    return fmt::format("method: analytic\nquality: {}\nformula: {}\nsteps: {}\n", QualityName(quality_),
                       steps_ == 0 ? "improved (one point)" : "initial (march)", steps_);
  }
  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    const size_t nw = model_.wavelengths();
    const glm::dvec3 x(0, 0, model_.bottom_radius_m + observer_altitude_m);
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
    out->assign(dirs.size() * nw, 0.0);
    for (size_t d = 0; d < dirs.size(); ++d) {
      const glm::dvec3 v = glm::normalize(glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]));
      sky_.Radiance(x, v, sun, steps_, out->data() + d * nw);
    }
  }
  // The Cloud Party sky is single scattering only (no ground reflection): all of Radiance.
  bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad,
                                const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const override {
    Radiance(observer_altitude_m, sun_zenith_rad, dirs, out);
    return true;
  }

 private:
  Quality quality_;
  AnalyticSky sky_;
  const AtmosphereModel& model_;
  int steps_ = 0;
};

}  // namespace

std::unique_ptr<SkyMethod> MakeAnalyticMethod(const AtmosphereModel& model, const SkyMethodOptions& options) {
  return std::make_unique<AnalyticMethod>(model, options);
}

}  // namespace skybake
