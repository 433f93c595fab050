#include "transport/orders/split.h"

#include <algorithm>

#include "transport/orders/grid.h"

namespace skybake::orders {

SplitSettings SplitParts(const OrdersSettings& s) {
  SplitSettings p{s, s};
  p.day.split_from_deg = 0.0;
  p.day.sun_max_deg = std::min(s.sun_max_deg, s.split_day_to_deg);
  p.day.sun_deg = SunNodes(p.day);
  // split_azimuths azimuths (16: at 8 the twilight sky's horizon band 90 deg from the sun's
  // azimuth was up to 5 % above the one solve's) with medium's kernel and cones (its
  // truncation_min_deg 0 reads as its truncation_deg, as in SettingsFor); high's view nodes,
  // whose first one below the horizon resolves the ground's dark band 1-2 deg down
  // (docs/sky-methods.md, "The twilight split").
  const OrdersSettings& med = OrdersPresets()[Quality::kMedium];
  OrdersSettings& t = p.twilight;
  t.split_from_deg = 0.0;
  t.nphi = s.split_azimuths;
  t.kernel_sub = med.kernel_sub;
  t.truncation_deg = med.truncation_deg;
  t.truncation_min_deg = med.truncation_min_deg > 0.0 && med.truncation_min_deg <= med.truncation_deg ? med.truncation_min_deg : med.truncation_deg;
  t.sun_min_deg = std::max(s.sun_min_deg, s.split_twilight_from_deg);
  t.dsa_from_tau = 0.0;  // its sun nodes from 88 deg: no diffusion correction (acceleration.h)
  t.sun_deg = SunNodes(t);
  return p;
}

double TwilightWeight(const OrdersSettings& s, double sun_zenith_rad) {
  const double u = std::clamp((sun_zenith_rad / kDeg - s.split_from_deg) / s.split_width_deg, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

void Blend(double w, const std::vector<double>& twilight, std::vector<double>* day) {
  for (size_t i = 0; i < day->size(); ++i) (*day)[i] += w * (twilight[i] - (*day)[i]);
}

}  // namespace skybake::orders
