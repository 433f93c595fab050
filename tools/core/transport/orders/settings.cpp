#include "transport/orders/settings.h"

#include "io/error.h"

namespace skybake::orders {

namespace {

void ApplyPreset(const std::string& quality, OrdersSettings* s) {
  if (quality == "low") {
    s->nr = 10, s->nup = 10, s->ndn = 6, s->nphi = 6, s->nt = 24, s->nss = 48, s->fine = 128, s->tolerance = 3e-3;
    s->sun_nr = 48;
  } else if (quality == "medium") {
    // the defaults of OrdersSettings
  } else if (quality == "high") {
    // Measured on the hazed sky (docs/sky-methods.md, "Scattering kernel"): the azimuth count and
    // a kernel that resolves the aerosol lobe matter; more radius nodes or ray steps do not. With
    // the 1 deg aerosol cone the multiple-scattering aureole of a low sun needs 36 azimuths
    // (hazed, sun 85 deg: 0.45 % RMS, max 1.19 %, against 0.53 / 2.11 % with 24). 96 view steps
    // are within 0.005 % RMS of 160, and medium's 1 deg twilight nodes within 0.2 % RMS of
    // 0.5 deg ones at sun 90-98 deg (the twilight target is 3 %).
    s->nup = 24, s->ndn = 12, s->nphi = 36, s->nss = 96, s->fine = 512, s->tolerance = 3e-4;
    s->kernel_sub = 4, s->truncation_deg = 3.0, s->truncation_min_deg = 1.0;
    s->sun_nr = 192;
  } else {
    throw UsageError("--quality: expected low, medium or high, got '" + quality + "'");
  }
}

// Sun zenith nodes: every sun_step_deg (10) up to 80, then low_sun_step_x10 / 10 (1 deg) to 90,
// twilight_step_x10 / 10 (1 deg) through the low sun and twilight to 110, then 112, 115, 120
// (beyond: no sunlight reaches the atmosphere's sunlit part that matters; J is taken as 0).
// From 80 to 90 deg the sources fall steeply and convexly: with the sun on the horizon, 1 deg
// nodes and the log-linear blend from 85 deg put the clear sky 0.5 deg above the horizon, 40 deg
// from the sun's azimuth, within 0.1 % of the path tracer (high; 387.1 cd/m2 +- 0.37 %).
std::vector<double> SunNodes(int sun_step, int low10, int tw10) {
  std::vector<double> deg;
  for (double a = 0; a < 80; a += sun_step) deg.push_back(a);
  for (double a = 80; a < 90 - 1e-9; a += low10 / 10.0) deg.push_back(a);
  double tw = 1.0;
  if (tw10 > 0) tw = tw10 / 10.0;
  for (double a = 90; a <= 110 + 1e-9; a += tw) deg.push_back(a);
  for (double a : {112.0, 115.0, 120.0}) deg.push_back(a);
  return deg;
}

}  // namespace

OrdersSettings SettingsFor(const SkyMethodOptions& o) {
  OrdersSettings s;
  ApplyPreset(o.quality, &s);
  auto get = [&](const char* key, int* v) {
    auto it = o.table_size.find(key);
    if (it != o.table_size.end()) *v = it->second;
  };
  // A switch: 0 off, anything else on.
  auto get_flag = [&](const char* key, bool* v) {
    auto it = o.table_size.find(key);
    if (it != o.table_size.end()) *v = it->second != 0;
  };
  // A positive integer key scaled by 1 / divisor; 0 or absent keeps the preset.
  auto get_scaled = [&](const char* key, double divisor, double* v) {
    int x = 0;
    get(key, &x);
    if (x > 0) *v = x / divisor;
  };
  get("radius", &s.nr);
  get("view_up", &s.nup);
  get("view_down", &s.ndn);
  get("azimuth", &s.nphi);
  get("ray_steps", &s.nt);
  get("view_steps", &s.nss);
  get_scaled("truncation_deg", 1.0, &s.truncation_deg);
  get_scaled("truncation_min_deg", 1.0, &s.truncation_min_deg);
  if (s.truncation_min_deg <= 0.0 || s.truncation_min_deg > s.truncation_deg) s.truncation_min_deg = s.truncation_deg;
  get_flag("normalise", &s.normalise);
  get_scaled("tau_cap", 1.0, &s.tau_cap);
  get("sun_radius_nodes", &s.sun_nr);
  get_scaled("sun_low_step_x100", 100.0, &s.sun_low_step_deg);
  int ksub = -1;
  get("kernel_sub", &ksub);
  if (ksub >= 0) s.kernel_sub = ksub;
  get_scaled("tail_share_pct", 100.0, &s.tail_share_max);
  get_flag("ss_scaled", &s.ss_scaled);
  get("ss_scaled_view", &s.ss_scaled_view);
  get_flag("kernel_modal", &s.kernel_modal);
  get_flag("gather_split", &s.gather_split);
  get_scaled("loglin_from_deg", 1.0, &s.loglin_from_deg);
  get_scaled("view_power_x10", 10.0, &s.view_power);
  get_scaled("rho_cap_pct", 100.0, &s.rho_cap);
  get_flag("azimuth_even", &s.azimuth_even);
  get_flag("early_tail", &s.early_tail);
  if (o.view_steps > 0) s.nss = o.view_steps;
  if (o.orders > 0) s.max_orders = o.orders;
  if (o.order_tolerance > 0) s.tolerance = o.order_tolerance;
  int sun_step = 10, low10 = 10, tw10 = 0;
  get("sun_step_deg", &sun_step);
  get("low_sun_step_x10", &low10);
  get("twilight_step_x10", &tw10);
  s.sun_deg = SunNodes(sun_step, low10, tw10);
  if (s.nr < 3 || s.nup < 2 || s.ndn < 2 || s.nphi < 2 || s.nt < 4 || s.nss < 4) {
    throw UsageError("orders: table sizes are too small");
  }
  return s;
}

}  // namespace skybake::orders
