#include "transport/orders/settings.h"

#include <fmt/format.h>

#include "io/error.h"
#include "transport/orders/split.h"

namespace skybake::orders {

const QualityTable<OrdersSettings>& OrdersPresets() {
  static const QualityTable<OrdersSettings> presets = {{
      // low
      OrdersSettings{.nr = 10, .nup = 10, .ndn = 6, .nphi = 6, .nt = 24, .nss = 48, .fine = 128, .sun_nr = 48,
                     .tolerance = 3e-3},
      // medium: the defaults of OrdersSettings
      OrdersSettings{},
      // high. Measured on the hazed sky (docs/sky-methods.md, "Scattering kernel"): the azimuth
      // count and a kernel that resolves the aerosol lobe matter; more radius nodes or ray steps do
      // not. With the 1 deg aerosol cone the multiple-scattering aureole of a low sun needs 36
      // azimuths (hazed, sun 85 deg: 0.45 % RMS, max 1.19 %, against 0.53 / 2.11 % with 24). 96
      // view steps are within 0.005 % RMS of 160, and medium's 1 deg twilight nodes within 0.2 %
      // RMS of 0.5 deg ones at sun 90-98 deg (the twilight target is 3 %). The twilight split
      // (split.h; docs/sky-methods.md "The twilight split"): these tables with the sun nodes to
      // 93 deg (22 of the 42: the tables to 92 deg move the sky at sun 90 deg by up to 0.1 %, to 93
      // deg by <= 0.006 %, in Y over 77 directions of the hazed sky on the 20 nm test grid, against
      // one solve of all 42), and 16 azimuths with medium's kernel and cones and high's view nodes
      // from 88 deg (26 nodes; from 85 deg the same to 0.01 % RMS), blended over sun zenith 90-91
      // deg. The twilight tables are within 1.0 % RMS (max 2.6 %) of one solve at high at sun
      // 91-105 deg over 77 directions of the clear, hazed, cloudy1 and cloudy3 skies on the 20 nm
      // test grid; with medium's 8 azimuths 2.5 % RMS (max 7.5 %: the horizon band 90 deg from
      // the sun's azimuth, and under the clouds 70-80 deg from the zenith towards the sun);
      // medium's view nodes would put the ground 1 deg below the horizon at 5x the one solve's
      // radiance (its first down node is 1.8 deg below the horizon, high's 0.7 deg).
      // Under a cloud every interval of the 16 radius nodes holding more than 0.15 of optical depth
      // is split into equal optical-depth pieces, up to 64 nodes (cloudy3: 38 nodes, 0.75 % RMS off
      // its sky with 92 nodes; +2 ... +6.6 % against its 1 % path reference with 16; docs/sky-methods.md
      // "Radius nodes under a cloud").
      OrdersSettings{.radius_dtau = 0.15, .nup = 24, .ndn = 12, .nphi = 36, .nss = 96, .fine = 512, .truncation_deg = 10.0,
                     .truncation_min_deg = 1.0, .cone_peaked_ratio = 2.0, .sun_nr = 192, .kernel_sub = 4, .tolerance = 3e-4,
                     .split_from_deg = 90.0, .split_width_deg = 1.0, .split_day_to_deg = 93.0, .split_twilight_from_deg = 88.0},
  }};
  return presets;
}

const std::vector<OrdersOverride>& OrdersOverrides() {
  using K = OrdersOverride::Kind;
  using S = OrdersSettings;
  constexpr int kMany = 4096;
  static const std::vector<OrdersOverride> overrides = {
      {"radius", K::kCount, 3, kMany, 1.0, &S::nr},
      {"view_up", K::kCount, 2, kMany, 1.0, &S::nup},
      {"view_down", K::kCount, 2, kMany, 1.0, &S::ndn},
      {"azimuth", K::kCount, 2, kMany, 1.0, &S::nphi},
      {"ray_steps", K::kCount, 4, kMany, 1.0, &S::nt},
      {"view_steps", K::kCount, 4, kMany, 1.0, &S::nss},
      {"radius_dtau_x100", K::kScaled, 0, 1000, 100.0, &S::radius_dtau},
      {"radius_max", K::kCount, 3, kMany, 1.0, &S::radius_max},
      {"truncation_deg", K::kScaled, 1, 90, 1.0, &S::truncation_deg},
      {"truncation_min_deg", K::kScaled, 1, 90, 1.0, &S::truncation_min_deg},
      {"cone_ratio_x10", K::kScaled, 11, 10000, 10.0, &S::cone_ratio},
      {"cone_peaked_ratio_x10", K::kScaled, 11, 10000, 10.0, &S::cone_peaked_ratio},
      {"normalise", K::kFlag, 0, 1, 1.0, &S::normalise},
      {"tau_cap", K::kScaled, 1, 1000, 1.0, &S::tau_cap},
      {"sun_radius_nodes", K::kCount, 2, kMany, 1.0, &S::sun_nr},
      {"sun_low_step_x100", K::kScaled, 1, 1000, 100.0, &S::sun_low_step_deg},
      {"kernel_sub", K::kCount, 0, 64, 1.0, &S::kernel_sub},
      {"tail_share_pct", K::kScaled, 1, 100, 100.0, &S::tail_share_max},
      {"ss_scaled", K::kFlag, 0, 1, 1.0, &S::ss_scaled},
      {"ss_scaled_view", K::kCount, 0, 2, 1.0, &S::ss_scaled_view},
      {"kernel_modal", K::kFlag, 0, 1, 1.0, &S::kernel_modal},
      {"gather_split", K::kFlag, 0, 1, 1.0, &S::gather_split},
      {"loglin_from_deg", K::kScaled, 1, 1000, 1.0, &S::loglin_from_deg},
      {"view_power_x10", K::kScaled, 1, 100, 10.0, &S::view_power},
      {"rho_cap_pct", K::kScaled, 1, 99, 100.0, &S::rho_cap},
      {"azimuth_even", K::kFlag, 0, 1, 1.0, &S::azimuth_even},
      {"early_tail", K::kFlag, 0, 1, 1.0, &S::early_tail},
      {"dsa_from_tau_x10", K::kScaled, 0, 10000, 10.0, &S::dsa_from_tau},
      {"sun_step_deg", K::kCount, 1, 80, 1.0, &S::sun_step_deg},
      {"low_sun_step_x10", K::kScaled, 1, 100, 10.0, &S::low_sun_step_deg},
      {"twilight_step_x10", K::kScaled, 1, 200, 10.0, &S::twilight_step_deg},
      {"split_from_deg", K::kScaled, 0, 180, 1.0, &S::split_from_deg},
      {"split_width_x10", K::kScaled, 1, 200, 10.0, &S::split_width_deg},
      {"split_day_to_deg", K::kScaled, 0, 180, 1.0, &S::split_day_to_deg},
      {"split_twilight_from_deg", K::kScaled, 0, 180, 1.0, &S::split_twilight_from_deg},
      {"split_azimuth", K::kCount, 2, kMany, 1.0, &S::split_azimuths},
      {"step_positions_mib", K::kCount, 0, kMany, 1.0, &S::step_positions_mib},
      {"solve_tables_mib", K::kCount, 1, kMany, 1.0, &S::solve_tables_mib},
      {"kernel_half", K::kFlag, 0, 1, 1.0, &S::kernel_half},
  };
  return overrides;
}

const std::vector<std::string>& OverrideKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (const OrdersOverride& o : OrdersOverrides()) k.push_back(o.key);
    return k;
  }();
  return keys;
}

namespace {

void Apply(const OrdersOverride& o, int value, OrdersSettings* s) {
  if (value < o.min || value > o.max) {
    throw UsageError(fmt::format("orders: expert override '{}': expected {} to {}, got {}", o.key, o.min, o.max, value));
  }
  if (auto* f = std::get_if<int OrdersSettings::*>(&o.field)) s->*(*f) = value;
  if (auto* f = std::get_if<bool OrdersSettings::*>(&o.field)) s->*(*f) = value != 0;
  if (auto* f = std::get_if<double OrdersSettings::*>(&o.field)) s->*(*f) = value / o.divisor;
}

}  // namespace

// Sun zenith nodes: every sun_step_deg (10) up to 80, then low_sun_step_deg (1 deg) to 90,
// twilight_step_deg (1 deg) through the low sun and twilight to 110, then 112, 115, 120
// (beyond: no sunlight reaches the atmosphere's sunlit part that matters; J is taken as 0).
// From 80 to 90 deg the sources fall steeply and convexly: with the sun on the horizon, 1 deg
// nodes and the log-linear blend from 85 deg put the clear sky 0.5 deg above the horizon, 40 deg
// from the sun's azimuth, within 0.1 % of the path tracer (high; 387.1 cd/m2 +- 0.37 %).
// Only the nodes within [sun_min_deg, sun_max_deg] are kept.
std::vector<double> SunNodes(const OrdersSettings& s) {
  std::vector<double> deg;
  auto add = [&](double a) {
    if (a >= s.sun_min_deg - 1e-9 && a <= s.sun_max_deg + 1e-9) deg.push_back(a);
  };
  for (double a = 0; a < 80; a += s.sun_step_deg) add(a);
  for (double a = 80; a < 90 - 1e-9; a += s.low_sun_step_deg) add(a);
  for (double a = 90; a <= 110 + 1e-9; a += s.twilight_step_deg) add(a);
  for (double a : {112.0, 115.0, 120.0}) add(a);
  return deg;
}

OrdersSettings SettingsFor(const SkyMethodOptions& o) {
  CheckOverrideKeys("orders", o.table_size, OverrideKeys());
  OrdersSettings s = OrdersPresets()[o.quality];
  for (const OrdersOverride& ov : OrdersOverrides()) {
    auto it = o.table_size.find(ov.key);
    if (it != o.table_size.end()) Apply(ov, it->second, &s);
  }
  if (s.truncation_min_deg <= 0.0 || s.truncation_min_deg > s.truncation_deg) s.truncation_min_deg = s.truncation_deg;
  if (o.view_steps > 0) s.nss = o.view_steps;
  if (o.orders > 0) s.max_orders = o.orders;
  if (o.order_tolerance > 0) s.tolerance = o.order_tolerance;
  s.sun_deg = SunNodes(s);
  if (s.sun_deg.size() < 2) throw UsageError("orders: fewer than 2 sun nodes in the sun range");
  if (s.split_from_deg > 0.0 && (s.split_day_to_deg < s.split_from_deg + s.split_width_deg - 1e-9 ||
                                 s.split_twilight_from_deg > s.split_from_deg + 1e-9)) {
    throw UsageError(fmt::format(
        "orders: the twilight split blends over sun zenith {} to {} deg, so its daylight part needs sun nodes to at least {} deg "
        "(split_day_to_deg: {}) and its twilight part from at most {} deg (split_twilight_from_deg: {})",
        s.split_from_deg, s.split_from_deg + s.split_width_deg, s.split_from_deg + s.split_width_deg, s.split_day_to_deg,
        s.split_from_deg, s.split_twilight_from_deg));
  }
  if (s.split_from_deg > 0.0) {
    const SplitSettings parts = SplitParts(s);
    if (parts.day.sun_deg.size() < 2 || parts.twilight.sun_deg.size() < 2) {
      throw UsageError("orders: fewer than 2 sun nodes in a part of the twilight split");
    }
  }
  if (s.nr < 3 || s.nup < 2 || s.ndn < 2 || s.nphi < 2 || s.nt < 4 || s.nss < 4) {
    throw UsageError("orders: table sizes are too small");
  }
  return s;
}

}  // namespace skybake::orders
