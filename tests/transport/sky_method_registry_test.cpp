// The options of the deterministic methods, defined once: the Quality enum and its names
// (transport/quality.h), the method registry (transport/sky_method.h), each method's preset table
// and the typed expert overrides of `orders` (transport/orders/settings.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <fmt/format.h>

#include "io/error.h"
#include "method_scenes.h"
#include "transport/method_analytic.h"
#include "transport/method_ms_approx.h"
#include "transport/method_single.h"
#include "transport/orders/nodes.h"
#include "transport/orders/settings.h"
#include "transport/orders/split.h"
#include "transport/quality.h"
#include "transport/sky_method.h"

using namespace skybake;
using namespace skybake::testing;

namespace {

// The message of the UsageError `f` throws ("" if none).
template <typename F>
std::string UsageMessage(F f) {
  try {
    f();
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Quality, NamesRoundTrip) {
  EXPECT_EQ(QualityNames(), (std::vector<std::string>{"low", "medium", "high"}));
  EXPECT_EQ(QualityNamesText(), "low, medium or high");
  for (Quality q : {Quality::kLow, Quality::kMedium, Quality::kHigh}) {
    EXPECT_EQ(FindQuality(QualityName(q)), q);
    EXPECT_EQ(ParseQuality(QualityName(q), "--quality"), q);
  }
  EXPECT_FALSE(FindQuality("Medium"));
  EXPECT_FALSE(FindQuality(""));
  EXPECT_EQ(UsageMessage([] { ParseQuality("best", "luts.quality"); }),
            "luts.quality: expected low, medium or high, got 'best'");
  EXPECT_EQ(SkyMethodOptions{}.quality, Quality::kMedium);
}

TEST(SkyMethodRegistry, NamesAndRows) {
  EXPECT_EQ(SkyMethodNames(), (std::vector<std::string>{"single", "orders", "ms-approx", "analytic"}));
  EXPECT_EQ(SegmentMethodNames(), (std::vector<std::string>{"orders"}));
  for (const SkyMethodEntry& e : SkyMethodRegistry()) {
    EXPECT_EQ(FindSkyMethod(e.name), &e);
    EXPECT_NE(e.make, nullptr) << e.name;
    // Only orders reads expert overrides.
    EXPECT_EQ(e.override_keys().empty(), std::string(e.name) != "orders") << e.name;
  }
  EXPECT_EQ(FindSkyMethod("path"), nullptr);
  const AtmosphereModel m = Homogeneous(6371e3, 100e3, {1e-5}, {0.0}, std::make_shared<IsotropicPhase>(), 0.0);
  EXPECT_EQ(UsageMessage([&] { MakeSkyMethod("magic", m, {}, {}); }),
            "--method: expected path, single, orders, ms-approx, analytic; got 'magic'");
  SkyMethodOptions low;
  low.quality = Quality::kLow;
  for (const std::string& name : SkyMethodNames()) EXPECT_EQ(MakeSkyMethod(name, m, low, {})->Name(), name);
}

// A key given to a method that reads none is an error naming the key, for every such method.
TEST(SkyMethodRegistry, MethodsWithoutOverridesRejectAnyKey) {
  const AtmosphereModel m = Homogeneous(6371e3, 100e3, {1e-5}, {0.0}, std::make_shared<IsotropicPhase>(), 0.0);
  SkyMethodOptions o;
  o.table_size["radius"] = 8;
  for (const char* name : {"single", "ms-approx", "analytic"}) {
    EXPECT_EQ(UsageMessage([&] { MakeSkyMethod(name, m, o, {}); }),
              std::string(name) + " reads no expert overrides, got 'radius'");
    SkyMethodOptions strided = o;
    strided.spectral_stride = 2;
    EXPECT_NE(UsageMessage([&] { MakeSkyMethod(name, m, strided, {}); }), "") << name;
  }
}

// An unknown key (a misspelt one) is an error naming it and listing the known keys, both through
// the registry and in SettingsFor itself.
TEST(OrdersOverrides, UnknownKeyIsAnErrorNamingIt) {
  SkyMethodOptions o;
  o.table_size["early_tial"] = 0;
  const std::string message = UsageMessage([&] { orders::SettingsFor(o); });
  EXPECT_EQ(message.rfind("orders: unknown expert override 'early_tial' (known: radius, view_up, ", 0), 0) << message;
  for (const std::string& key : orders::OverrideKeys()) EXPECT_NE(message.find(key), std::string::npos) << key;
  const AtmosphereModel m = Homogeneous(6371e3, 100e3, {1e-5}, {0.0}, std::make_shared<IsotropicPhase>(), 0.0);
  EXPECT_EQ(UsageMessage([&] { MakeSkyMethod("orders", m, o, {}); }), message);
}

// The known keys are the typed table's, each once; a value outside a key's range is an error.
TEST(OrdersOverrides, KeysDerivedFromTheTypedTable) {
  const std::vector<std::string>& keys = orders::OverrideKeys();
  EXPECT_EQ(keys.size(), orders::OrdersOverrides().size());
  EXPECT_EQ(std::set<std::string>(keys.begin(), keys.end()).size(), keys.size());
  for (const orders::OrdersOverride& ov : orders::OrdersOverrides()) {
    EXPECT_LE(ov.min, ov.max) << ov.key;
    SkyMethodOptions o;
    o.table_size[ov.key] = ov.max + 1;
    EXPECT_EQ(UsageMessage([&] { orders::SettingsFor(o); }),
              fmt::format("orders: expert override '{}': expected {} to {}, got {}", ov.key, ov.min, ov.max, ov.max + 1));
    if (ov.kind == orders::OrdersOverride::Kind::kFlag) {
      EXPECT_EQ(ov.max, 1) << ov.key;
    }
  }
}

// Each kind of key sets its setting: a count as is, a flag, a scaled integer divided.
TEST(OrdersOverrides, EachKindSetsItsSetting) {
  SkyMethodOptions o;
  o.quality = Quality::kLow;
  o.table_size = {{"radius", 12},          {"azimuth", 7},        {"early_tail", 0},          {"kernel_sub", 0},
                  {"sun_low_step_x100", 5}, {"view_power_x10", 15}, {"tail_share_pct", 20},      {"ss_scaled_view", 2},
                  {"truncation_deg", 4},    {"truncation_min_deg", 2}, {"low_sun_step_x10", 5}, {"twilight_step_x10", 20},
                  {"sun_step_deg", 20}};
  const orders::OrdersSettings s = orders::SettingsFor(o);
  EXPECT_EQ(s.nr, 12);
  EXPECT_EQ(s.nphi, 7);
  EXPECT_FALSE(s.early_tail);
  EXPECT_EQ(s.kernel_sub, 0);
  EXPECT_DOUBLE_EQ(s.sun_low_step_deg, 0.05);
  EXPECT_DOUBLE_EQ(s.view_power, 1.5);
  EXPECT_DOUBLE_EQ(s.tail_share_max, 0.2);
  EXPECT_EQ(s.ss_scaled_view, 2);
  EXPECT_DOUBLE_EQ(s.truncation_deg, 4.0);
  EXPECT_DOUBLE_EQ(s.truncation_min_deg, 2.0);
  // Sun nodes: 0, 20, 40, 60; 80 to 89.5 by 0.5; 90 to 110 by 2; 112, 115, 120.
  EXPECT_EQ(s.sun_deg.size(), 4u + 20u + 11u + 3u);
  EXPECT_DOUBLE_EQ(s.sun_deg[4], 80.0);
  EXPECT_DOUBLE_EQ(s.sun_deg[5], 80.5);
  // The rest stays the low preset's.
  EXPECT_EQ(s.nup, 10);
  EXPECT_EQ(s.sun_nr, 48);
}

// The twilight split's parts: the daylight one with high's tables and its sun nodes to 93 deg,
// the twilight one with high's view nodes, 16 azimuths, medium's kernel and cones and its sun
// nodes from 88 deg;
// a split whose parts do not reach across the blend zone is an error.
TEST(OrdersOverrides, TwilightSplitParts) {
  SkyMethodOptions o;
  o.quality = Quality::kHigh;
  const orders::OrdersSettings s = orders::SettingsFor(o);
  EXPECT_EQ(s.sun_deg.size(), 42u);
  const orders::SplitSettings p = orders::SplitParts(s);
  EXPECT_EQ(p.day.split_from_deg, 0.0);
  EXPECT_EQ(p.twilight.split_from_deg, 0.0);
  EXPECT_EQ(p.day.sun_deg.size(), 22u);
  EXPECT_EQ(p.day.sun_deg.back(), 93.0);
  EXPECT_EQ(std::vector<int>({p.day.nup, p.day.ndn, p.day.nphi, p.day.kernel_sub}), std::vector<int>({24, 12, 36, 4}));
  EXPECT_EQ(p.twilight.sun_deg.size(), 26u);
  EXPECT_EQ(p.twilight.sun_deg.front(), 88.0);
  EXPECT_EQ(std::vector<int>({p.twilight.nup, p.twilight.ndn, p.twilight.nphi, p.twilight.kernel_sub, p.twilight.nr, p.twilight.nss}),
            std::vector<int>({24, 12, 16, 0, 16, 96}));
  EXPECT_EQ(p.twilight.truncation_deg, 5.0);
  EXPECT_EQ(p.twilight.truncation_min_deg, 5.0);
  EXPECT_EQ(orders::TwilightWeight(s, 90.0 * kDeg), 0.0);
  EXPECT_DOUBLE_EQ(orders::TwilightWeight(s, 90.5 * kDeg), 0.5);
  EXPECT_EQ(orders::TwilightWeight(s, 91.0 * kDeg), 1.0);
  o.table_size["split_day_to_deg"] = 90;
  EXPECT_NE(UsageMessage([&] { orders::SettingsFor(o); }).find("split_day_to_deg: 90"), std::string::npos);
  o.table_size = {{"split_from_deg", 150}, {"split_day_to_deg", 160}, {"split_twilight_from_deg", 150}};
  EXPECT_EQ(UsageMessage([&] { orders::SettingsFor(o); }), "orders: fewer than 2 sun nodes in a part of the twilight split");
  o.table_size = {{"split_from_deg", 0}, {"split_day_to_deg", 90}};
  EXPECT_EQ(orders::SettingsFor(o).split_from_deg, 0.0);
  o.table_size = {{"split_azimuth", 12}};
  EXPECT_EQ(orders::SplitParts(orders::SettingsFor(o)).twilight.nphi, 12);
}

// The preset tables hold the documented values (docs/sky-methods.md, "Qualities").
TEST(Presets, OrdersTable) {
  const auto& p = orders::OrdersPresets();
  const orders::OrdersSettings& lo = p[Quality::kLow];
  EXPECT_EQ(std::vector<int>({lo.nr, lo.nup, lo.ndn, lo.nphi, lo.nt, lo.nss, lo.fine, lo.sun_nr, lo.kernel_sub}),
            std::vector<int>({10, 10, 6, 6, 24, 48, 128, 48, 0}));
  EXPECT_EQ(lo.tolerance, 3e-3);
  EXPECT_EQ(lo.truncation_deg, 5.0);
  const orders::OrdersSettings& me = p[Quality::kMedium];
  EXPECT_EQ(std::vector<int>({me.nr, me.nup, me.ndn, me.nphi, me.nt, me.nss, me.fine, me.sun_nr, me.kernel_sub}),
            std::vector<int>({16, 16, 8, 8, 40, 64, 256, 96, 0}));
  EXPECT_EQ(me.tolerance, 1e-3);
  EXPECT_EQ(me.truncation_deg, 5.0);
  EXPECT_EQ(me.truncation_min_deg, 0.0);
  const orders::OrdersSettings& hi = p[Quality::kHigh];
  EXPECT_EQ(std::vector<int>({hi.nr, hi.nup, hi.ndn, hi.nphi, hi.nt, hi.nss, hi.fine, hi.sun_nr, hi.kernel_sub}),
            std::vector<int>({16, 24, 12, 36, 40, 96, 512, 192, 4}));
  EXPECT_EQ(hi.tolerance, 3e-4);
  EXPECT_EQ(hi.truncation_deg, 10.0);
  EXPECT_EQ(hi.truncation_min_deg, 1.0);
  // The cone rule's fall per azimuth interval: 10x, 2x for cloud droplets at high (medium.cpp).
  EXPECT_EQ(std::vector<double>({lo.cone_ratio, me.cone_ratio, hi.cone_ratio}), std::vector<double>({10.0, 10.0, 10.0}));
  EXPECT_EQ(std::vector<double>({lo.cone_peaked_ratio, me.cone_peaked_ratio, hi.cone_peaked_ratio}), std::vector<double>({10.0, 10.0, 2.0}));
  // The twilight split (transport/orders/split.h): high only.
  EXPECT_EQ(std::vector<double>({hi.split_from_deg, hi.split_width_deg, hi.split_day_to_deg, hi.split_twilight_from_deg}),
            std::vector<double>({90.0, 1.0, 93.0, 88.0}));
  EXPECT_EQ(hi.split_azimuths, 16);
  EXPECT_EQ(lo.split_from_deg, 0.0);
  EXPECT_EQ(me.split_from_deg, 0.0);
  // Radius nodes by the column's optical depth (docs/sky-methods.md "Radius nodes under a cloud"):
  // high only, intervals over 0.15 split, up to 64.
  EXPECT_EQ(std::vector<double>({lo.radius_dtau, me.radius_dtau, hi.radius_dtau}), std::vector<double>({0.0, 0.0, 0.15}));
  EXPECT_EQ(hi.radius_max, 64);
  for (const orders::OrdersSettings* s : {&lo, &me, &hi}) {
    EXPECT_EQ(s->max_orders, 40);
    EXPECT_EQ(s->sun_low_step_deg, 0.1);
    EXPECT_TRUE(s->kernel_modal && s->gather_split && s->ss_scaled && s->early_tail && s->normalise);
  }
  // SettingsFor with no overrides is the preset plus its sun nodes (medium: 8 + 10 + 21 + 3).
  SkyMethodOptions o;
  EXPECT_EQ(orders::SettingsFor(o).sun_deg.size(), 42u);
  EXPECT_EQ(orders::SettingsFor(o).truncation_min_deg, 5.0);  // 0: the same as truncation_deg
}

// The radius nodes: the preset's nr nodes uniform in s(h), and every interval of them whose
// vertical optical depth exceeds radius_dtau split into equal optical-depth pieces, never more
// than radius_max nodes in all (the pieces then grow), the nr nodes alone when radius_dtau is 0
// or radius_max is below nr. A synthetic column: 0.1 of air (scale height 8 km) and a 2 km
// layer of optical depth tau_c at 3.5-5.5 km, uniform in extinction.
TEST(Presets, RadiusNodesFollowTheOpticalDepth) {
  const double H = 100e3;
  double tau_c = 0.0;
  auto tau_of = [&](double h) { return 0.1 * (1.0 - std::exp(-h / 8000.0)) + tau_c * std::clamp((h - 3500.0) / 2000.0, 0.0, 1.0); };
  orders::OrdersSettings s;
  s.nr = 16, s.radius_dtau = 0.15, s.radius_max = 64;
  const std::vector<double> clear = orders::RadiusNodeAltitudes(s, tau_of, H);
  ASSERT_EQ(clear.size(), 16u);  // no interval of the clear column holds 0.15
  EXPECT_EQ(clear.front(), 0.0);
  EXPECT_NEAR(clear.back(), H, 1e-3);
  auto max_piece = [&](const std::vector<double>& h) {
    double d = 0.0;
    for (size_t i = 0; i + 1 < h.size(); ++i) {
      EXPECT_LT(h[i], h[i + 1]) << i;
      d = std::max(d, tau_of(h[i + 1]) - tau_of(h[i]));
    }
    return d;
  };
  tau_c = 2.0;
  const std::vector<double> thin = orders::RadiusNodeAltitudes(s, tau_of, H);
  EXPECT_GT(thin.size(), 16u);
  EXPECT_LE(thin.size(), 64u);
  EXPECT_LE(max_piece(thin), 0.15 * (1.0 + 1e-6));  // every piece within radius_dtau
  // The base nodes of the same column are all kept (refinement only adds).
  orders::OrdersSettings base = s;
  base.radius_dtau = 0.0;
  for (double h : orders::RadiusNodeAltitudes(base, tau_of, H)) {
    EXPECT_TRUE(std::any_of(thin.begin(), thin.end(), [&](double x) { return std::abs(x - h) < 1e-9; })) << h;
  }
  tau_c = 16.0;  // would need > 100 pieces of 0.15: capped at 64, the pieces as even as the cap allows
  const std::vector<double> thick = orders::RadiusNodeAltitudes(s, tau_of, H);
  EXPECT_GE(thick.size(), 60u);
  EXPECT_LE(thick.size(), 64u);
  EXPECT_LT(max_piece(thick), 0.4);  // 16 over the ~48 pieces the cap leaves the layer
  s.radius_max = 10;  // a cap below nr: the nr nodes
  EXPECT_EQ(orders::RadiusNodeAltitudes(s, tau_of, H).size(), 16u);
  s.radius_max = 64, s.radius_dtau = 0.0;
  EXPECT_EQ(orders::RadiusNodeAltitudes(s, tau_of, H).size(), 16u);
}

TEST(Presets, SingleMsApproxAnalyticTables) {
  struct March {
    double dz_min, dz_rel, piece;
    int rings, sectors, mu, r;
  };
  const March want[] = {{500, 0.3, 100e3, 0, 4, 64, 16}, {150, 0.12, 30e3, 1, 4, 128, 32}, {50, 0.05, 10e3, 3, 6, 256, 64}};
  struct Lut {
    int mu_s, z, sqrt_dirs;
    double dz_min, dz_rel, piece;
  };
  const Lut want_ms[] = {{16, 16, 4, 1000, 0.5, 200e3}, {32, 32, 8, 300, 0.25, 50e3}, {64, 64, 16, 100, 0.1, 20e3}};
  const int want_steps[] = {0, 20, 200};
  for (int i = 0; i < kQualityCount; ++i) {
    const Quality q = static_cast<Quality>(i);
    const MarchSettings s = SingleMarchSettings(q);
    EXPECT_EQ(s.dz_min_m, want[i].dz_min) << i;
    EXPECT_EQ(s.dz_rel, want[i].dz_rel) << i;
    EXPECT_EQ(s.max_piece_m, want[i].piece) << i;
    EXPECT_EQ(s.disk_rings, want[i].rings) << i;
    EXPECT_EQ(s.disk_sectors, want[i].sectors) << i;
    EXPECT_EQ(s.table_mu, want[i].mu) << i;
    EXPECT_EQ(s.table_r, want[i].r) << i;
    const MsApproxSettings ms = MsApproxPreset(q);
    EXPECT_EQ(ms.march.dz_min_m, s.dz_min_m) << i;  // the view rays march as `single`
    EXPECT_EQ(ms.march.table_mu, s.table_mu) << i;
    EXPECT_EQ(ms.lut_mu_s, want_ms[i].mu_s) << i;
    EXPECT_EQ(ms.lut_z, want_ms[i].z) << i;
    EXPECT_EQ(ms.sqrt_dirs, want_ms[i].sqrt_dirs) << i;
    EXPECT_EQ(ms.ray_dz_min_m, want_ms[i].dz_min) << i;
    EXPECT_EQ(ms.ray_dz_rel, want_ms[i].dz_rel) << i;
    EXPECT_EQ(ms.ray_max_piece_m, want_ms[i].piece) << i;
    EXPECT_EQ(ms.orders, 0) << i;
    EXPECT_EQ(AnalyticSteps()[q], want_steps[i]) << i;
  }
}
