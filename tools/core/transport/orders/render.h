// The output of `orders`: L = L_1 + L_ms per direction. L_1, single scattering (and the ground's
// reflection of the direct sun), exactly for every output direction: a march along the view ray
// with the full tabulated phase functions and the disk-averaged sun transmittance. L_ms from the
// table at the observer radius, linear in the view and azimuth nodes and log-linear in the sun
// angle (twilight light decays exponentially with the sun's depression). A view segment's
// in-scattered radiance: L_1 along the segment plus int T* J_ms* dt from the tabulated sources.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "transport/orders/solve.h"
#include "transport/view_segment.h"

namespace skybake::orders {

// A view ray's sun-independent part.
struct ViewPoint {
  double t = 0.0, rr = 0.0, mu2 = 0.0;
  Lerp sun_r;  // the sun transmittance table's radius position
};
struct ViewRay {
  double mu = 2.0;  // none yet
  double length = 0.0;
  bool ground = false;
  std::vector<ViewPoint> pts;
  std::vector<float> e;      // [(p * nc + c) * nw + w]: half-step x T(0, t_p) x sigma_s,c (single scattering weight)
  std::vector<float> seg;    // [p * nw + w]: half-step x T*(0, t_p) x sigma_s* (segments' multiple scattering)
  std::vector<float> t_end;  // [w] transmittance to the ray's end (the ground)
};

// Whole view rays (no segment) from an observer altitude along mu: built by `build` on the first
// request and kept, up to kMaxCachedRays rays (then built anew each time). A ray depends on
// (altitude, mu) only, so a cached one is the same bytes as a new one, whichever thread built it
// first. The LUT render's 16 ambient rings are the same in each of its 64 sun slices (its rows are
// not: the GT7 mapping's view zenith follows the sun); keeping them saves 0.2-0.4 s of a 32x128
// LUT at 48 wavelengths (docs/benchmarks.md).
class ViewRayCache {
 public:
  template <class Build>
  std::shared_ptr<const ViewRay> Get(double altitude_m, double mu, Build&& build) {
    const std::pair<double, double> key{altitude_m, mu};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = rays_.find(key);
      if (it != rays_.end()) return it->second;
    }
    auto ray = std::make_shared<ViewRay>();
    build(ray.get());
    std::lock_guard<std::mutex> lock(mutex_);
    if (rays_.size() >= kMaxCachedRays) return ray;
    return rays_.emplace(key, std::move(ray)).first->second;
  }

 private:
  static constexpr size_t kMaxCachedRays = 64;  // ~0.15 MB each at 48 wavelengths and 4 components
  std::mutex mutex_;
  std::map<std::pair<double, double>, std::shared_ptr<const ViewRay>> rays_;
};

struct RenderInputs {
  const AtmosphereModel* m = nullptr;
  const Medium* md = nullptr;
  const SunTables* sun = nullptr;
  const Nodes* nodes = nullptr;
  const OrdersSettings* s = nullptr;
  const SolveResult* res = nullptr;
  bool ss_scaled = false;  // the sun's path attenuated by the delta-scaled medium (OrdersSettings::ss_scaled)
  ViewRayCache* cache = nullptr;
};

// Sky radiance (segment == nullptr) or a view segment's in-scattered radiance, [d * nw + w].
// With `single`, also L_1 alone (sky radiance only).
void Render(const RenderInputs& in, double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
            const ViewSegment* segment, std::vector<double>* out, std::vector<double>* single);

}  // namespace skybake::orders
