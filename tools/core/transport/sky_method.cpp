#include "transport/sky_method.h"

#include <glm/geometric.hpp>

#include <fmt/format.h>

#include "io/error.h"
#include "transport/path_tracer.h"
#include "transport/single_scattering.h"

namespace skybake {

namespace {

// `single`: the deterministic quadrature of the single-scattering integral
// (transport/single_scattering.h) plus the ground's first reflection of the direct sun for view
// rays that end on the ground. Quality: the view-ray piece length and the sun-disk points.
class SingleMethod : public SkyMethod {
 public:
  SingleMethod(const AtmosphereModel& model, const SkyMethodOptions& o) : model_(model) {
    if (o.quality == "low") {
      settings_.max_piece_m = 1000.0;
      settings_.disk_rings = 0;
    } else if (o.quality == "medium") {
      settings_.max_piece_m = 300.0;
      settings_.disk_rings = 1;
      settings_.disk_sectors = 4;
    } else if (o.quality == "high") {
      settings_.max_piece_m = 100.0;
      settings_.disk_rings = 3;
      settings_.disk_sectors = 6;
    } else {
      throw UsageError("--quality: expected low, medium or high, got '" + o.quality + "'");
    }
  }
  std::string Name() const override { return "single"; }
  std::string Describe() const override {
    return fmt::format("method: single\nview_piece_m: {}\nsun_disk_points: {}\n", settings_.max_piece_m,
                       settings_.disk_rings <= 0 ? 1 : settings_.disk_rings * settings_.disk_sectors);
  }
  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    const size_t nw = model_.wavelengths();
    std::vector<size_t> all(nw);
    for (size_t i = 0; i < nw; ++i) all[i] = i;
    const glm::dvec3 x(0, 0, model_.bottom_radius_m + observer_altitude_m);
    const glm::dvec3 sun = DirectionFromAngles(sun_zenith_rad, 0.0);
    out->assign(dirs.size() * nw, 0.0);
    for (size_t d = 0; d < dirs.size(); ++d) {
      const glm::dvec3 v = glm::normalize(glm::dvec3(dirs[d][0], dirs[d][1], dirs[d][2]));
      std::vector<double> L = SingleScattering(model_, x, v, sun, all, settings_);
      // Ground reflection of the direct sun (first order) at the end of a downward view ray.
      bool blocked = false;
      for (size_t w = 0; w < nw; ++w) {
        const double tau_view = OpticalDepth(model_, x, v, INFINITY, w, &blocked);
        if (blocked) {
          const double b = glm::dot(x, v);
          const double t = -b - std::sqrt(std::max(0.0, b * b - (glm::dot(x, x) - model_.bottom_radius_m * model_.bottom_radius_m)));
          const glm::dvec3 g = x + t * v;
          const glm::dvec3 n = glm::normalize(g);
          const double mu_s = glm::dot(n, sun);
          bool shadow = false;
          if (mu_s > 0.0) {
            const double tau_sun = OpticalDepth(model_, g + n * 1e-3, sun, INFINITY, w, &shadow);
            if (!shadow) {
              L[w] += model_.ground_albedo[w] / 3.14159265358979323846 * mu_s * model_.sun.irradiance[w] *
                      std::exp(-tau_sun) * std::exp(-tau_view);
            }
          }
        }
        (*out)[d * nw + w] = L[w];
      }
    }
  }

 private:
  const AtmosphereModel& model_;
  SingleScatteringSettings settings_;
};

}  // namespace

std::vector<std::string> SkyMethodNames() { return {"single"}; }

std::unique_ptr<SkyMethod> MakeSkyMethod(const std::string& name, const AtmosphereModel& model,
                                         const SkyMethodOptions& options, const ProgressFn& progress) {
  if (name == "single") return std::make_unique<SingleMethod>(model, options);
  std::string known;
  for (const std::string& n : SkyMethodNames()) known += (known.empty() ? "" : ", ") + n;
  throw UsageError("--method: expected path, " + known + "; got '" + name + "'");
}

}  // namespace skybake
